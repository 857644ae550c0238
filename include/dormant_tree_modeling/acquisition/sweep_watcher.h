#pragma once

#include <optional>

namespace dormant_tree_modeling {
namespace acquisition {

/// @brief A rotary sweep found in the stage's positions: the stage turned from before one end
/// of [theta_min, theta_max] past the other without reversing.
struct WatchedSweep {
  double begin = 0.0;  ///< s, stamp where the monotonic run began
  double end = 0.0;    ///< s, stamp of the first position past the far end
  bool upwards = true;
};

/// @brief Finds the rotary sweeps in a stream of stamped stage positions, so that views can be
/// assembled from a recording (rosbag replay) without commanding the stage. A run is a stretch
/// of positions moving one way; reversals count only beyond a tolerance, so feedback jitter at
/// standstill neither splits nor starts a run, and pauses (step-and-scan) do not end one. A run
/// that started at or before one end and reaches the other completes a sweep, once.
class SweepWatcher {
 public:
  /// @param theta_min, theta_max rad, the sweep's range (theta_min < theta_max)
  /// @param tolerance rad, movement against the run's direction that counts as a reversal
  /// @throws Error INVALID_ARGUMENT on a bad range or tolerance
  SweepWatcher(double theta_min, double theta_max, double tolerance = 1e-3);

  /// @brief Feed one position (stamps in time order; older or non-finite samples are ignored).
  /// @returns the sweep this sample completes, if any
  std::optional<WatchedSweep> add(double stamp, double theta);

  /// @brief Forget the current run (e.g. after time jumped back in a replay).
  void reset();

 private:
  double theta_min_, theta_max_, tolerance_;
  bool started_ = false, reported_ = false;
  int direction_ = 0;  // +1 up, -1 down, 0 not yet moving
  double last_stamp_ = 0.0;
  double run_begin_ = 0.0, run_theta0_ = 0.0;   // where the run started
  double extreme_stamp_ = 0.0, extreme_ = 0.0;  // furthest point along the run so far
};

}  // namespace acquisition
}  // namespace dormant_tree_modeling
