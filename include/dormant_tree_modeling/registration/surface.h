#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "dormant_tree_modeling/modeling/geometry_fit.h"
#include "dormant_tree_modeling/registration/branch_axes.h"

namespace dormant_tree_modeling {
namespace registration {

using modeling::Points;

/// @brief Points with what registration needs to match them: PCA normals turned towards the
/// sensors that saw the points, so that the front and the back half of a trunk or branch are
/// never taken for one surface.
struct Surface {
  Points points;
  /// Unit normals, turned towards view_dirs where those are set; zero where undefined.
  Points normals;
  /// Unit directions from each point towards the sensor(s) that saw it; zero where unknown or
  /// where the point merges returns seen from opposite sides (a thin branch).
  Points view_dirs;

  std::size_t size() const { return points.size(); }
};

/// @brief The mean of the points (zero for none).
Eigen::Vector3d centroid(const Points& pts);

/// @brief View directions of points seen from one sensor position (same frame).
Points viewDirections(const Points& pts, const Eigen::Vector3d& sensor);

/// @brief Voxel-average points and view directions, then estimate oriented normals.
/// @param pts points
/// @param view_dirs one per point, or empty when unknown (normals stay unoriented)
/// @param voxel voxel edge, m
/// @param normal_neighbors k of the PCA normals
Surface makeSurface(const Points& pts, const Points& view_dirs, double voxel, int normal_neighbors);

/// @brief The surface moved by a rigid transform.
Surface transformed(const Surface& s, const Eigen::Isometry3d& t);

/// @brief Append b to a.
void append(Surface& a, const Surface& b);

/// @brief One surface per voxel size, coarse to fine: the levels of coarse-to-fine ICP.
struct Pyramid {
  std::vector<double> voxels;
  std::vector<Surface> levels;
  /// Branch-axis samples (estimateAxes); empty when not estimated. The finest level's ICP
  /// pairs them across opposite sides.
  AxisSamples axes;
};

/// @brief Build a pyramid; levels follow `voxels` (coarse to fine).
Pyramid makePyramid(const Points& pts, const Points& view_dirs, const std::vector<double>& voxels,
                    int normal_neighbors);

/// @brief The pyramid moved by a rigid transform.
Pyramid transformed(const Pyramid& p, const Eigen::Isometry3d& t);

/// @brief Append b's levels and axes to a's (same voxel sizes; an empty a takes b's).
void append(Pyramid& a, const Pyramid& b);

}  // namespace registration
}  // namespace dormant_tree_modeling
