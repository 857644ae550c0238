#pragma once

#include <Eigen/Geometry>
#include <string>
#include <vector>

namespace dormant_tree_modeling {

template <typename Config>
class ConfigTable;

namespace acquisition {

/// @brief The acquisition plan of the paper's Algorithm 1 (docs/hardware.md): per side of the row,
/// platform positions at two heights, two positions per height about 1 m apart, and at each
/// position several views stepping the linear slide. Lengths in m, angles in degrees.
struct ViewPlanConfig {
  std::vector<double> heights_m = {1.5, 4.0};  ///< laser height above the ground
  int positions_per_height = 2;
  double position_spacing_m = 1.0;  ///< along the row
  int slide_steps = 5;              ///< views per platform position
  double slide_step_m = 0.10;       ///< slide move between views
  double standoff_m = 1.5;          ///< horizontal distance from the row to the rotation axis
  bool front = true;                ///< scan from y < 0
  bool back = true;                 ///< scan from y > 0
  double theta_min_deg = -45.0;     ///< rotary sweep: theta_min <= theta < theta_max
  double theta_max_deg = 45.0;
  double theta_step_deg = 0.45;  ///< one scan line per step: 200 lines

  /// @brief Scan lines per view.
  int linesPerView() const;
  /// @brief @throws Error INVALID_ARGUMENT naming the bad field.
  void validate() const;
};

/// @brief One planned view.
struct PlannedView {
  int index = 0;           ///< 0-based, in acquisition order
  int platform_index = 0;  ///< which platform position the view belongs to
  std::string side;        ///< "front" or "back"
  Eigen::Isometry3d platform = Eigen::Isometry3d::Identity();  ///< true platform pose
  double slide = 0.0;                                          ///< carriage position, m
};

/// @brief Expand a plan into its views (40 with the defaults).
std::vector<PlannedView> makeViewPlan(const ViewPlanConfig& config);

/// @brief The keys of a view plan: YAML loading, validation and docs/configuration.md.
const ConfigTable<ViewPlanConfig>& viewPlanConfigTable();

/// @brief Load a plan from YAML (the keys of viewPlanConfigTable(); missing keys keep defaults).
/// @throws Error FILE_NOT_FOUND, PARSE_ERROR, INVALID_ARGUMENT
ViewPlanConfig loadViewPlan(const std::string& path);

}  // namespace acquisition
}  // namespace dormant_tree_modeling
