#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "dormant_tree_modeling/modeling/geometry_fit.h"

namespace dormant_tree_modeling {
namespace registration {

using modeling::Points;

/// @brief Point-to-plane ICP, coarse to fine. Lengths in m, angles in degrees.
struct IcpConfig {
  /// Voxel sizes of the levels, coarse to fine; each level's correspondence limit is
  /// distance_factor x its voxel (a wide basin first, a tight fit last).
  std::vector<double> voxels = {0.04, 0.02, 0.01};
  double distance_factor = 4.0;
  int max_iterations = 30;             ///< per level
  double trim = 0.8;                   ///< share of the closest correspondences used
  double huber = 0.01;                 ///< m: residuals beyond count linearly (robust to clutter)
  int normal_neighbors = 12;           ///< k for the target's PCA normals
  double min_rotation_step = 0.005;    ///< deg: converged below both steps
  double min_translation_step = 1e-4;  ///< m
  /// @throws Error INVALID_ARGUMENT naming the bad field
  void validate() const;
};

/// @brief Result of one alignment.
struct IcpResult {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();  ///< source -> target
  double rmse = 0;  ///< m, over the used correspondences at the finest level
  double overlap =
      0;  ///< share of source points (finest level) with a target point within its limit
  int iterations = 0;      ///< over all levels
  bool converged = false;  ///< the finest level converged before max_iterations
};

/// @brief Align source to target from an initial guess (source -> target).
/// @throws Error EMPTY_INPUT when either cloud has fewer than 10 points
IcpResult alignPointToPlane(const Points& source, const Points& target,
                            const Eigen::Isometry3d& guess, const IcpConfig& config = {});

}  // namespace registration
}  // namespace dormant_tree_modeling
