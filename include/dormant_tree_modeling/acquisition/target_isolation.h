#pragma once

#include <optional>

#include <Eigen/Core>
#include <cstddef>

#include "dormant_tree_modeling/common/cloud.h"

namespace dormant_tree_modeling {
namespace acquisition {

/// @brief How the target tree is cut out of one view (the paper cropped by hand). Lengths in m.
struct IsolationConfig {
  double ground_margin = 0.05;        ///< points this close above the ground level are ground
  double ground_min_fraction = 0.02;  ///< a ground level needs this share of the points
  /// With the plan's ground level given, a level found further from it than this (m) is not
  /// the ground (a dense layer of branches or wires seen from above): the plan's is used.
  double ground_hint_tolerance = 0.25;
  double trunk_band_low = 0.1;   ///< the trunk is searched between these heights above
  double trunk_band_high = 0.8;  ///< the ground (or over all heights without ground)
  double cell = 0.04;            ///< grid cell of the trunk search
  /// Columns score lower with their distance from the expected trunk position (Gaussian of
  /// this sigma): keeps the search off the trellis posts and the neighbours in the row.
  double hint_sigma_m = 0.25;
  /// The columns scoring at least this share of the best (up to max_candidates) are compared
  /// by the branch points around them: in a ring of branch_ring_inner..branch_ring_outer (m)
  /// around the column, branch_ring_low..branch_ring_high (m) above the ground. A trunk has
  /// branches there; a post or a neighbour's trunk within the hint's reach has fewer.
  double candidate_ratio = 0.2;
  std::size_t max_candidates = 30;
  double branch_ring_inner = 0.12, branch_ring_outer = 0.4;
  double branch_ring_low = 0.8, branch_ring_high = 2.5;
  double min_distance = 0.3;   ///< the trunk lies this far ahead of the sensor at least
  double max_distance = 4.0;   ///< and at most (the next row is ~3.5 m away)
  double crop_radius_m = 0.7;  ///< kept around the trunk axis (neighbours ~0.9-1.2 m away)
  double max_height_m = 5.5;   ///< kept up to this height above the ground
  /// Upright columns (posts, a neighbour's trunk) further than this from the trunk are cut
  /// out over their whole height, within other_column_radius of their cells.
  double trunk_clearance = 0.15;
  double other_column_radius = 0.1;
  double component_cell = 0.05;           ///< connectivity grid of the component filter
  std::size_t min_component_points = 30;  ///< smaller isolated components are dropped

  /// @throws Error INVALID_ARGUMENT naming the bad field
  void validate() const;
};

/// @brief What isolation did.
struct IsolationResult {
  CloudPtr cloud;                                   ///< the target tree
  Eigen::Vector2d trunk = Eigen::Vector2d::Zero();  ///< x, y of the trunk axis
  bool ground_found = false;      ///< a ground level is known (seen, or the plan's)
  bool ground_from_plan = false;  ///< it is the plan's: none seen near it
  double ground_z = 0.0;
  std::size_t ground_removed = 0, outside_removed = 0, small_component_points = 0;
};

/// @brief Cut the target tree out of a view: find the ground level, find the trunk as the
/// densest vertical column ahead of the sensor near where the plan expects it, with branches
/// around it, keep a cylinder around it, drop small isolated components. The cloud's frame
/// must have z up.
/// @param sensor sensor position in the cloud's frame
/// @param forward horizontal direction the sensor faces (towards the row)
/// @param hint expected trunk position (x, y) in the cloud's frame, from the view plan
/// @param ground_hint the ground's height in the cloud's frame as the plan knows it (the
///        laser's height below the platform frame); used when none is seen near it: from high
///        views the ground is sparse and the trunk's base hidden, and the trunk search
///        needs the band just above the ground
/// @throws Error EMPTY_INPUT when the view holds no tree ahead of the sensor
IsolationResult isolateTarget(const Cloud& cloud, const Eigen::Vector3d& sensor,
                              const Eigen::Vector3d& forward, const Eigen::Vector2d& hint,
                              const IsolationConfig& config,
                              std::optional<double> ground_hint = std::nullopt);

}  // namespace acquisition
}  // namespace dormant_tree_modeling
