#pragma once

#include <Eigen/Geometry>
#include <vector>

#include "dormant_tree_modeling/registration/surface.h"

namespace dormant_tree_modeling {
namespace registration {

/// @brief Point-to-plane ICP, coarse to fine. Lengths in m, angles in degrees.
struct IcpConfig {
  /// Voxel sizes of the levels, coarse to fine; each level's correspondence limit is
  /// distance_factor x its voxel (a wide basin first, a tight fit last).
  std::vector<double> voxels_m = {0.04, 0.02, 0.01};
  double distance_factor = 4.0;
  int max_iterations = 30;    ///< per level
  double trim = 0.8;          ///< share of the closest correspondences used
  double huber_m = 0.01;      ///< m: residuals beyond count linearly (robust to clutter)
  int normal_neighbors = 12;  ///< k for the PCA normals
  /// Points whose view directions (towards their sensors) meet below this cosine were seen
  /// from opposite sides: they lie on opposite halves of a branch, a diameter apart along the
  /// ray, so such a pair only counts its offset across the target point's ray (point-to-ray).
  /// Point-to-plane on them would pull the back of the tree into the front by ~1.3 radii.
  double across_cos = -0.3;
  /// At the finest level, pair branch-axis samples (Pyramid::axes) of opposite sides and count
  /// their offset across the target's axis; point pairs of opposite sides then only count
  /// towards the overlap. Off: point-to-ray pairs, which leave the depth along the rays free.
  bool axis_pairs = true;
  double axis_max_angle_deg = 20.0;  ///< paired axes at most this far from parallel
  /// m: a source point counts towards the overlap when a target point lies this close (across
  /// the ray for pairs seen from opposite sides); ~2.5 sigma of the range noise.
  double overlap_distance_m = 0.015;
  /// deg and m: converged below both steps (at the finest level; coarser levels scale them
  /// with their voxel size)
  double min_rotation_step_deg = 0.005;
  double min_translation_step_m = 1e-4;
  /// @throws Error INVALID_ARGUMENT naming the bad field
  void validate() const;
};

/// @brief Result of one alignment.
struct IcpResult {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();  ///< source -> target
  double rmse = 0;  ///< m, point-to-plane (axis pairs: across the axis), used pairs, last level
  double overlap =
      0;  ///< share of source points (last level) within overlap_distance of the target
  int iterations = 0;      ///< over all levels
  bool converged = false;  ///< the last level converged before max_iterations
  /// Smallest eigenvalue of the normalised point-to-plane information (1 = every direction
  /// equally constrained, 0 = a direction the surfaces leave free, e.g. sliding along a trunk).
  double conditioning = 0;
};

/// @brief Align source to target, both pyramids with the config's voxel sizes.
/// @param guess initial source -> target transform
/// @param first_level skip the coarser levels (refinement from a good guess)
/// @param last_level stop after this level (-1: the finest; quick scoring of candidates)
/// @throws Error EMPTY_INPUT when a level holds fewer than 10 points or nothing overlaps
IcpResult alignPyramids(const Pyramid& source, const Pyramid& target,
                        const Eigen::Isometry3d& guess, const IcpConfig& config,
                        int first_level = 0, int last_level = -1);

/// @brief Align plain point sets (unoriented normals).
/// @throws Error EMPTY_INPUT when either cloud has fewer than 10 points
IcpResult alignPointToPlane(const Points& source, const Points& target,
                            const Eigen::Isometry3d& guess, const IcpConfig& config = {});

}  // namespace registration
}  // namespace dormant_tree_modeling
