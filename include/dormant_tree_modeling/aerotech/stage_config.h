#pragma once

#include <string>

#include "dormant_tree_modeling/aerotech/ensemble_client.h"
#include "dormant_tree_modeling/geometry/stage_kinematics.h"

namespace dormant_tree_modeling {
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
  geometry::StageGeometry geometry;
  double joint_state_rate = 50.0;  ///< Hz
  bool home_on_start = true;
  double move_timeout_margin_s = 3.0;  ///< beyond the move's nominal duration

  /// @throws Error INVALID_ARGUMENT naming the field
  void validate() const;
};

}  // namespace aerotech
}  // namespace dormant_tree_modeling
