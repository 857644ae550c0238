#pragma once

#include <memory>
#include <string>

#include "dormant_tree_modeling/aerotech/ensemble_client.h"
#include "dormant_tree_modeling/aerotech/stage_config.h"

namespace dormant_tree_modeling {
namespace aerotech {

/// @brief A move as the `~move_axis` service asks for it (service units: deg or m).
struct MoveRequest {
  std::string axis;  ///< controller axis name or joint name
  double target = 0;
  double velocity = 0;  ///< 0: the axis's default
  bool relative = false;
  bool wait = true;
};

/// @brief How a move or homing ended; the ROS service replies carry it as `status`.
enum class MoveStatus {
  OK,         ///< in position (or moving, for a move that does not wait), or homed
  NOT_READY,  ///< the stage is still connecting or setting up: the same request may succeed later
  REFUSED,    ///< the request is invalid (unknown axis, non-finite value, beyond the soft limits)
  FAILED,     ///< the controller failed it (axis fault, timeout, lost connection)
};

/// @brief What became of a move.
struct MoveResult {
  MoveStatus status = MoveStatus::FAILED;
  std::string message;
  double position = 0;  ///< feedback after the command, service units

  bool success() const { return status == MoveStatus::OK; }
};

/// @brief Feedback of both axes, sampled together.
struct StageFeedback {
  double rotary = 0;  ///< deg
  double slide = 0;   ///< m
};

/// @brief Axis state for diagnostics.
struct StageHealth {
  AxisStatus rotary_status, slide_status;
  std::uint32_t rotary_faults = 0, slide_faults = 0;
};

/// @brief The rotary stage and the slide behind one Ensemble: unit conversion, soft limits,
/// moves that wait with a deadline derived from the distance, homing, and a second socket for
/// feedback so that position sampling never waits behind a blocking HOME. ROS-free.
class StageController {
 public:
  /// @throws Error INVALID_ARGUMENT for a bad configuration
  explicit StageController(StageConfig config);

  /// @brief Acknowledge faults, enable both axes, home them when configured.
  /// @throws Error IO_FAILURE with the controller's reason
  void setUp();
  /// @brief Move one axis; failures (limits, faults, timeouts, lost connection) come back in
  /// the result, decoded, never as an exception.
  MoveResult move(const MoveRequest& request);
  /// @brief Acknowledge faults, enable and home the rotary stage, then the slide.
  MoveResult home();
  /// @brief Both positions. @throws Error IO_FAILURE
  StageFeedback feedback();
  /// @brief Status and fault words of both axes. @throws Error IO_FAILURE
  StageHealth health();
  /// @brief Make the blocking calls of other threads (set-up, feedback, a move being waited
  /// for) return at once with an error: the first step of shutting down.
  void interrupt();
  /// @brief Abort both axes, best effort, within `deadline_s` (shutdown; a controller that
  /// does not answer must not hold the node up).
  void stopAll(double deadline_s = 1.0);
  /// @brief The axis configuration named by controller axis or joint name, or null.
  const StageAxisConfig* axis(const std::string& name) const;
  const StageConfig& config() const { return config_; }
  /// @brief Reconnections of the command and feedback sockets so far.
  std::uint64_t reconnects() const;

 private:
  StageConfig config_;
  EnsembleClient command_, feedback_;
};

}  // namespace aerotech
}  // namespace dormant_tree_modeling
