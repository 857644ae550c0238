#include "dormant_tree_modeling/lms111/clock_mapper.h"

#include <algorithm>
#include <limits>

namespace dormant_tree_modeling {
namespace lms111 {

namespace {

// The fitted drift is trusted once the window spans this much device time; before, the
// oscillators are assumed equal (their difference is then well under a ray period).
constexpr double MIN_SPAN_FOR_DRIFT_S = 2.0;
constexpr double WRAP_S = 4294967296.0 * 1e-6;

}  // namespace

void ClockMapper::reset() {
  samples_.clear();
  slope_ = 1.0;
  offset_ = 0.0;
  origin_ = 0.0;
}

double ClockMapper::unwrap(std::uint32_t device_us) const {
  // Signed difference modulo 2^32 from the last raw value: forward across a wrap is positive.
  const auto delta = static_cast<std::int32_t>(device_us - last_raw_);
  return last_device_s_ + delta * 1e-6;
}

bool ClockMapper::observe(std::uint32_t device_us, double host_s) {
  bool restarted = false;
  double device_s = device_us * 1e-6;
  if (!samples_.empty()) {
    device_s = unwrap(device_us);
    const Sample& last = samples_.back();
    // Backwards, or a jump the host clock did not see: the device rebooted.
    const double device_step = device_s - last.device_s;
    const double host_step = host_s - last.host_s;
    if (device_step < 0.0 || std::abs(device_step - host_step) > 1.0 + 0.01 * host_step) {
      reset();
      device_s = device_us * 1e-6;
      restarted = true;
    }
  }
  last_raw_ = device_us;
  last_device_s_ = device_s;
  if (samples_.empty())
    origin_ = device_s;
  samples_.push_back({device_s, host_s});
  while (samples_.size() > 2 && samples_.back().device_s - samples_.front().device_s > window_s_)
    samples_.pop_front();
  fit();
  return restarted;
}

void ClockMapper::fit() {
  const double span = samples_.back().device_s - samples_.front().device_s;
  double slope = 1.0;
  if (samples_.size() >= 10 && span >= MIN_SPAN_FOR_DRIFT_S) {
    double mx = 0, my = 0;
    for (const auto& s : samples_) {
      mx += s.device_s - origin_;
      my += s.host_s;
    }
    mx /= samples_.size();
    my /= samples_.size();
    double sxy = 0, sxx = 0;
    for (const auto& s : samples_) {
      const double dx = s.device_s - origin_ - mx;
      sxy += dx * (s.host_s - my);
      sxx += dx * dx;
    }
    if (sxx > 0)
      slope = std::clamp(sxy / sxx, 1.0 - max_drift_, 1.0 + max_drift_);
  }
  slope_ = slope;
  double lowest = std::numeric_limits<double>::infinity();
  for (const auto& s : samples_)
    lowest = std::min(lowest, s.host_s - slope_ * (s.device_s - origin_));
  offset_ = lowest;
}

std::optional<double> ClockMapper::toHost(std::uint32_t device_us) const {
  if (samples_.empty())
    return std::nullopt;
  const double device_s = unwrap(device_us);
  return offset_ + slope_ * (device_s - origin_);
}

}  // namespace lms111
}  // namespace dormant_tree_modeling
