#pragma once

#include <cstdint>
#include <map>
#include <mutex>
#include <set>
#include <string>
#include <vector>

namespace dormant_tree_modeling {
namespace emulation {

/// @brief One emulated axis: its limits and motion capability, in controller units (deg for a
/// rotary stage, mm for a linear one) and seconds.
struct EmulatedAxisConfig {
  std::string name = "X";
  double max_velocity = 90.0;   ///< units/s; faster requests are clamped
  double acceleration = 360.0;  ///< units/s^2, trapezoidal profiles
  double home_velocity = 30.0;  ///< units/s while homing
  double min_limit = -180.0;    ///< hard limits: reaching one faults the axis
  double max_limit = 180.0;
  double initial_position = 0.0;  ///< where the axis is at power-up (not homed)
};

/// @brief The project's stage as emulated: rotary stage "X" (deg, ART310-like: 180 deg/s,
/// +/-360 deg) and linear slide "Y" (mm, ATS02060-like: 600 mm travel, 200 mm/s).
std::vector<EmulatedAxisConfig> defaultStageAxes();

/// @brief Failures to show, for tests.
struct EnsembleFaults {
  std::string fault_axis;        ///< axis whose fault_on_move-th move faults half-way ("" off)
  int fault_on_move = 0;         ///< 1 = its first move
  std::uint32_t fault_bits = 1;  ///< AXISFAULT bits to raise (default: position error)
  std::size_t drop_after_commands = 0;     ///< close the socket after this many commands (0 off)
  std::set<std::string> invalid_commands;  ///< command words answered with '!'
  double idle_timeout_s = 0.0;  ///< close a socket idle this long, as the controller does (0 off)
  /// AXISSTATUS reports a move this long after it began (before: in position, no move), while
  /// PLANESTATUS reports it at once: the window a client checking AXISSTATUS alone falls into.
  double axis_status_latency_s = 0.0;
};

/// @brief A reply and the time it becomes due (HOME and moves in WAIT MODE MOVEDONE block).
struct EnsembleResponse {
  std::string line;       ///< without the line end
  double ready_at_s = 0;  ///< send no earlier than this
};

/// @brief The Ensemble's ASCII interpreter with a kinematic model of its axes (trapezoidal
/// moves, homing, free run, hard limits, faults that disable the axis), without I/O.
/// Thread-safe: the LMS111 emulator reads axis positions while the server drives it.
class EmulatedEnsemble {
 public:
  /// @throws Error INVALID_ARGUMENT for duplicate axis names or inconsistent limits
  explicit EmulatedEnsemble(std::vector<EmulatedAxisConfig> axes, EnsembleFaults faults = {});

  /// @brief Interpret one command line at time now_s (s, the server's steady clock).
  EnsembleResponse handle(const std::string& line, double now_s);
  /// @brief Position of an axis at a time (controller units). @throws Error INVALID_ARGUMENT
  double position(const std::string& axis, double now_s) const;
  const EnsembleFaults& faults() const { return faults_; }

 private:
  struct Axis {
    EmulatedAxisConfig config;
    bool enabled = false, homed = false, homing = false;
    std::uint32_t fault = 0;
    // The current motion segment: from p0 at t0 towards p1, cruising at v with acceleration a.
    double t0 = 0, p0 = 0, p1 = 0, v = 0, a = 1;
    bool freerun = false;
    double fault_at = -1.0;  // time at which the running move faults (-1 none)
    std::uint32_t fault_pending = 0;
  };
  Axis* find(const std::string& name);
  const Axis* find(const std::string& name) const;
  double positionAt(const Axis& axis, double t) const;
  double velocityAt(const Axis& axis, double t) const;
  double moveEnd(const Axis& axis) const;
  std::uint32_t planeStatus(double now_s) const;
  void settle(Axis& axis, double now_s);
  void startMove(Axis& axis, double target, double velocity, double now_s);
  void stop(Axis& axis, double now_s);
  EnsembleResponse motion(Axis& axis, double now_s);

  std::map<std::string, Axis> axes_;
  std::vector<std::string> order_;  // for @index addressing
  EnsembleFaults faults_;
  bool wait_mode_nowait_ = false;
  int moves_ = 0;
  mutable std::mutex mutex_;
};

}  // namespace emulation
}  // namespace dormant_tree_modeling
