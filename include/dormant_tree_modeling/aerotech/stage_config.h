#pragma once

#include <string>

#include "dormant_tree_modeling/aerotech/ensemble_client.h"
#include "dormant_tree_modeling/geometry/stage_kinematics.h"

namespace dormant_tree_modeling {

template <typename Config>
class ConfigTable;

namespace aerotech {

/// @brief One stage axis as the rest of the system sees it. Positions in service units: deg for
/// the rotary stage, m for the slide; the controller may count in others (mm), see scale.
struct StageAxisConfig {
  std::string axis;               ///< controller axis name ("X") or index ("@0")
  std::string joint;              ///< JointState / tf joint name
  double scale = 1.0;             ///< controller units per service unit (slide: 1000 mm per m)
  double default_velocity = 1.0;  ///< service units per s, used when a request gives 0
  double min_position = -1.0;     ///< soft limits, service units
  double max_position = 1.0;

  /// @throws Error INVALID_ARGUMENT naming the field
  void validate(const std::string& which) const;
};

/// @brief The rotary stage and linear slide, their controller and their mounting.
struct StageConfig {
  EnsembleClientConfig controller;
  StageAxisConfig rotary{"X", "rotary_stage_joint", 1.0, 30.0, -100.0, 100.0};
  StageAxisConfig slide{"Y", "slide_joint", 1000.0, 0.05, 0.0, 0.6};
  /// Mounting: the platform frame at the slide's centre (the ATS02060 travels 0.6 m).
  geometry::StageGeometry geometry{Eigen::Vector3d(0.0, -0.3, 0.0)};
  double joint_state_rate_hz = 50.0;  ///< position feedback -> joint_states and tf
  bool home_on_start = true;
  double move_timeout_margin_s = 3.0;  ///< beyond the move's nominal duration

  /// @throws Error INVALID_ARGUMENT naming the field
  void validate() const;
};

/// @brief The stage controller node's parameters (config/stage_controller.yaml).
struct StageNodeConfig {
  StageConfig stage;
  std::string platform_frame = "platform";
  std::string slide_base_frame = "slide_base";
  std::string slide_carriage_frame = "slide_carriage";
  std::string rotary_stage_frame = "rotary_stage";
  std::string laser_frame = "laser";
  double reconnect_min_s = 0.2;  ///< first back-off after a failed set-up or feedback round
  double reconnect_max_s = 5.0;  ///< the back-off doubles up to this
  /// @throws Error INVALID_ARGUMENT naming the field
  void validate() const;
};

/// @brief The keys of the stage controller node: YAML, its parameters, docs/configuration.md.
const ConfigTable<StageNodeConfig>& stageNodeConfigTable();

}  // namespace aerotech
}  // namespace dormant_tree_modeling
