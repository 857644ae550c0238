#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "dormant_tree_modeling/acquisition/sweep_assembler.h"

namespace dormant_tree_modeling {
namespace acquisition {

/// @brief How a view's rotary sweep is run (angles in degrees).
struct SweepConfig {
  bool continuous = true;        ///< false: step-and-scan (the paper's)
  double theta_min_deg = -45.0;  ///< the sweep covers theta_min_deg <= theta < theta_max_deg
  double theta_max_deg = 45.0;
  double theta_step_deg = 0.45;  ///< one scan line per step
  double margin_deg = 0.5;       ///< past each end, for the stage to reach speed (continuous)
  double settle_s = 0.02;        ///< after a step before a line counts (step-and-scan)
  /// @throws Error INVALID_ARGUMENT naming the bad field
  void validate() const;
};

/// @brief What a sweep needs from the stage and the laser (the node gives ROS services and
/// topics, the benchmark the core clients). Each throws Error on failure.
struct SweepIo {
  std::function<double()> now;              ///< the clock the scans are stamped with
  std::function<double()> rotary_position;  ///< deg
  std::function<void(double, double)>
      move_rotary;                      ///< target deg, velocity deg/s (0 default); waits
  std::function<double()> scan_period;  ///< s, of the streaming laser
  /// The buffered lines stamped in [t0, t1].
  std::function<std::vector<SweepLine>(double, double)> lines_between;
  /// The first line stamped after t, waiting up to a timeout (s); nothing on timeout.
  std::function<std::optional<SweepLine>(double, double)> first_line_after;
  /// The stage positions recorded so far.
  std::function<StagePositionHistory()> history;
};

/// @brief Run one sweep and assemble its range image. A continuous sweep starts from the end
/// the stage is nearer to (views alternate direction, no return move) and turns at one θ step
/// per scan period; step-and-scan moves, settles and takes one line per step.
/// @param dropped lines without stage coverage
/// @param missing rows of the plan's θ grid that no line filled (lost scans)
/// @throws Error IO_FAILURE from the stage or the laser, EMPTY_INPUT for a sweep without lines
RangeImage runSweep(const SweepIo& io, const SweepConfig& settings, std::size_t* dropped,
                    std::size_t* missing = nullptr);

}  // namespace acquisition
}  // namespace dormant_tree_modeling
