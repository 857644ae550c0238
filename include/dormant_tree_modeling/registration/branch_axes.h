#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "dormant_tree_modeling/modeling/geometry_fit.h"

namespace dormant_tree_modeling {
namespace registration {

using modeling::Points;

/// @brief How branch axes are estimated from one side (registration.yaml `axis_*`; the
/// silhouette growth from the sensor calibration). Lengths in m.
///
/// Why: a station sees only the half of each branch that faces it, and the station on the
/// other side of the row sees the other half. Nearest points of the two halves are a diameter
/// apart along the ray and say nothing about where the branch is along that ray, so ICP cannot
/// tell a back station that sits a few millimetres too close. The axis of a branch is the one
/// thing both sides see at the same place: each side estimates it from its own half (the
/// silhouette gives the radius, the visible surface the depth).
struct AxisConfig {
  double patch_m = 0.1;       ///< diameter of the neighbourhood one axis sample is fitted on
  int min_points = 15;        ///< fewer points in a patch: no sample
  double linearity = 2.0;     ///< largest / second PCA eigenvalue at least this (a stick)
  double max_view_cos = 0.5;  ///< |axis . view direction| at most this (seen from the side)
  /// Mean resultant length of the patch's view directions at least this: one side only.
  double min_view_agreement = 0.95;
  double min_radius_m = 0.003;  ///< samples outside [min, max] radius are dropped (forks, trunk)
  double max_radius_m = 0.04;
  /// How much wider than its diameter a thin branch's one-sided silhouette looks: a beam
  /// partly on a branch still returns with the branch's range, so the visible width is
  /// 2 r + silhouette_growth_m + silhouette_growth_per_m x range. The scanner's own (its beam
  /// and detection threshold): from the sensor calibration (calibrate_diameters on the rig's
  /// views). 0 and 0: an ideal beam.
  double silhouette_growth_m = 0.0;
  double silhouette_growth_per_m = 0.0;
  /// How much of a diameter change the width shows (the calibration's diameter_gain): the
  /// radius is half the width less the growth, divided by it. 1: an ideal beam's.
  double silhouette_diameter_gain = 1.0;
  /// Samples whose silhouette is wider than max_width_m + max_width_per_m x range are dropped:
  /// the widths the calibration's rods showed (its largest rod's, + COVERAGE_RADIUS_SLACK).
  /// Its silhouette model holds there, and a sample centred on the visible surface holds a
  /// wider silhouette only in part (its patch cuts it: read thin, its axis too near the
  /// sensor). 0 and 0: no limit (no calibration).
  double max_width_m = 0.0;
  double max_width_per_m = 0.0;
  /// @throws Error INVALID_ARGUMENT naming the bad field
  void validate() const;
};

/// @brief Branch-axis samples in one frame (parallel arrays).
struct AxisSamples {
  Points points;               ///< on the estimated axis
  Points directions;           ///< unit axis directions (sign arbitrary)
  Points view_dirs;            ///< unit directions towards the sensor that saw the half
  std::vector<double> radii;   ///< m, estimated from the silhouette
  std::vector<double> ranges;  ///< m, the patch's median distance to its sensor

  std::size_t size() const { return points.size(); }
};

/// @brief Estimate branch-axis samples around sample centres from points seen from one side.
/// @param pts the points (one station: one side of the tree)
/// @param view_dirs unit directions from each point towards its sensor
/// @param ranges each point's distance to its sensor (m): the beam footprint
/// @param centres where samples are tried (e.g. the 2 cm voxel centres)
/// @throws Error INVALID_ARGUMENT when the arrays differ in size or the config is bad
AxisSamples estimateAxes(const Points& pts, const Points& view_dirs,
                         const std::vector<double>& ranges, const Points& centres,
                         const AxisConfig& config);

/// @brief Append b moved by t to a.
void appendTransformed(AxisSamples& a, const AxisSamples& b, const Eigen::Isometry3d& t);

}  // namespace registration
}  // namespace dormant_tree_modeling
