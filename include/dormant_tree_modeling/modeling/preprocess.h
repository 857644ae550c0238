#pragma once

#include "dormant_tree_modeling/modeling/geometry_fit.h"
#include "dormant_tree_modeling/modeling/modeler_config.h"

namespace dormant_tree_modeling {
namespace modeling {

/// @brief What preprocessing removed, for the model's diagnostics.
struct PreprocessStats {
  std::size_t input = 0;
  std::size_t far_outliers = 0;  ///< stray points far outside the bulk of the cloud, dropped
  std::size_t after_voxel = 0;
  std::size_t capped = 0;    ///< merged by a coarser grid to stay within max_modeled_points
  double voxel_size = 0.0;   ///< the last grid used (m); coarser than voxel_size when capped > 0
  std::size_t floating = 0;  ///< isolated returns and mixed pixels (Eq. 1's targets)
  std::size_t ground = 0;
  std::size_t wires = 0;
  std::vector<Eigen::Vector3d> wire_directions;  ///< unit, one per wire removed
  double floating_radius = 0.0;  ///< neighbourhood radius used for floating pixels (m)
};

class PointIndex;

/// @brief Drops the points far outside the cloud's bulk (a stray return at 10 km is bad data,
/// and it would size every grid of the modeler): beyond FAR_OUTLIER_MARGIN times the extent of
/// the 1st to 99th percentile box, and at least FAR_OUTLIER_MIN_MARGIN_M, on any axis.
/// @returns how many were dropped
std::size_t removeFarOutliers(Points& pts);

/// @brief Median distance from a point to its nearest neighbour (on a sample of the points;
/// neighbours chosen in single precision, as PointIndex does).
double medianSpacing(const Points& pts);

/// @brief medianSpacing with an index of pts that already exists.
double medianSpacing(const Points& pts, const PointIndex& index);

/// @brief Voxel-grid downsampling: the centroid of the points in each occupied voxel, in a
/// deterministic order (sorted by voxel key).
Points voxelDownsample(const Points& pts, double voxel);

/// @brief Points with fewer than min_neighbors others within radius (single-precision
/// distances, as PointIndex measures them): floating pixels.
std::vector<char> floatingMask(const Points& pts, double radius, int min_neighbors);

/// @brief Downsample and, with config.preprocess.remove_clutter, drop floating pixels, the ground
/// plane and trellis wires (long straight thin near-horizontal runs); then, above
/// config.preprocess.max_points, downsample again on coarser grids.
Points preprocess(const Points& pts, const ModelerConfig& config, PreprocessStats* stats);

}  // namespace modeling
}  // namespace dormant_tree_modeling
