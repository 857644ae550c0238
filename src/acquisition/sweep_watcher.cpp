#include "dormant_tree_modeling/acquisition/sweep_watcher.h"

#include <cmath>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace acquisition {

SweepWatcher::SweepWatcher(double theta_min, double theta_max, double tolerance)
    : theta_min_(theta_min), theta_max_(theta_max), tolerance_(tolerance) {
  if (!(std::isfinite(theta_min) && std::isfinite(theta_max) && theta_min < theta_max))
    throw Error(ErrorCode::INVALID_ARGUMENT, "sweep watcher: need theta_min < theta_max");
  if (!(tolerance > 0 && tolerance < theta_max - theta_min))
    throw Error(ErrorCode::INVALID_ARGUMENT,
                "sweep watcher: the reversal tolerance must be > 0 and below the sweep range");
}

void SweepWatcher::reset() {
  started_ = false;
  reported_ = false;
  direction_ = 0;
}

std::optional<WatchedSweep> SweepWatcher::add(double stamp, double theta) {
  if (!std::isfinite(stamp) || !std::isfinite(theta) || (started_ && stamp <= last_stamp_))
    return std::nullopt;
  last_stamp_ = stamp;
  if (!started_) {
    started_ = true;
    run_begin_ = extreme_stamp_ = stamp;
    run_theta0_ = extreme_ = theta;
    return std::nullopt;
  }
  if (direction_ == 0) {
    if (std::abs(theta - run_theta0_) <= tolerance_) {
      // Still standing: the run begins at the last standstill sample.
      run_begin_ = extreme_stamp_ = stamp;
      run_theta0_ = extreme_ = theta;
      return std::nullopt;
    }
    direction_ = theta > run_theta0_ ? 1 : -1;
  }
  const double along = direction_ * (theta - extreme_);
  if (along >= 0) {
    extreme_ = theta;
    extreme_stamp_ = stamp;
  } else if (-along <= tolerance_) {
    // Standing at the turning point (feedback jitter): a run back starts when it leaves.
    extreme_stamp_ = stamp;
  } else {
    // Reversed: a new run starts where the old one turned.
    run_begin_ = extreme_stamp_;
    run_theta0_ = extreme_;
    direction_ = -direction_;
    extreme_ = theta;
    extreme_stamp_ = stamp;
    reported_ = false;
  }
  if (reported_)
    return std::nullopt;
  const bool up = direction_ > 0;
  const bool from_end = up ? run_theta0_ <= theta_min_ : run_theta0_ >= theta_max_;
  const bool past_far_end = up ? theta >= theta_max_ : theta <= theta_min_;
  if (!(from_end && past_far_end))
    return std::nullopt;
  reported_ = true;
  return WatchedSweep{run_begin_, stamp, up};
}

}  // namespace acquisition
}  // namespace dormant_tree_modeling
