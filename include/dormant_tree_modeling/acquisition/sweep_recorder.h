#pragma once

#include <deque>
#include <mutex>
#include <optional>
#include <vector>

#include "dormant_tree_modeling/acquisition/sweep.h"
#include "dormant_tree_modeling/acquisition/sweep_assembler.h"

namespace dormant_tree_modeling {
namespace acquisition {

/// @brief What a sweep reads while it runs: the laser's recent scan lines and the rotary
/// stage's stamped positions, filled from other threads (topic callbacks, driver and feedback
/// threads) and read by runSweep through bind(). Thread-safe.
class SweepRecorder {
 public:
  /// @param buffer_s scan lines older than this (by stamp, against the newest) are dropped
  /// @param max_position_gap_s see StagePositionHistory
  explicit SweepRecorder(double buffer_s = 60.0, double max_position_gap_s = 0.1)
      : buffer_s_(buffer_s), history_(max_position_gap_s) {}

  /// @brief A scan line and the laser's scan period (s).
  void addLine(SweepLine line, double scan_period);
  /// @brief A rotary position (rad) at a stamp.
  void addPosition(double stamp, double theta);

  std::vector<SweepLine> linesBetween(double t0, double t1) const;
  /// @brief The first line stamped after t, waiting up to timeout_s (wall time) for it.
  std::optional<SweepLine> firstLineAfter(double t, double timeout_s) const;
  StagePositionHistory history() const;
  /// @brief The latest rotary position, rad.
  double rotaryPosition() const;
  /// @brief The laser's scan period, if a line stamped within max_age of now arrived.
  std::optional<double> scanPeriod(double now, double max_age) const;

  /// @brief Set io's rotary_position (deg), lines_between, first_line_after and history
  /// (after a short wait for the feedback of the sweep's last moments) to these buffers; the
  /// caller sets now, move_rotary and scan_period.
  void bind(SweepIo& io) const;

 private:
  double buffer_s_;
  mutable std::mutex mutex_;
  std::deque<SweepLine> lines_;
  StagePositionHistory history_;
  double period_ = 0.0, theta_ = 0.0;
};

}  // namespace acquisition
}  // namespace dormant_tree_modeling
