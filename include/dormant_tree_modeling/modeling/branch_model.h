#pragma once

#include <string>
#include <vector>

#include "dormant_tree_modeling/modeling/geometry_fit.h"
#include "dormant_tree_modeling/modeling/modeler_config.h"
#include "dormant_tree_modeling/modeling/point_index.h"
#include "dormant_tree_modeling/modeling/trunk_model.h"

namespace dormant_tree_modeling {
namespace modeling {

/// @brief One primary branch found on the trunk.
struct BranchFit {
  Cylinder cylinder;           ///< axis points away from the trunk
  int trunk_segment = 0;       ///< index into TrunkModel::cylinders
  std::vector<int> inliers;    ///< indices into the modeled cloud
  std::size_t candidates = 0;  ///< points of its candidate cluster within the fit length
  Eigen::Vector3d attachment = Eigen::Vector3d::Zero();  ///< on the trunk axis
  /// False when its points start away from the trunk surface and only other returns fill the
  /// way there (a crossing branch took its near part): it yields to a duplicate that reaches it.
  bool reaches_surface = true;
};

/// @brief A branch candidate that was turned down, and why (for diagnostics).
struct RejectedBranch {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  ///< of the candidate's points
  int points = 0;
  std::string reason;  ///< "too few points", "no fit", "off its ray", "not radial", "points
                       ///< down", "thicker than the trunk", "misses the trunk", "not at the
                       ///< surface", "too short", "too low", "a wire" (the wire's points),
                       ///< "duplicate"; with " (search budget spent)" when it was not split
                       ///< for lack of budget, and "remainder not searched (search budget
                       ///< spent)" for what an extraction left
};

/// @brief Whether two detections are one branch (a gap in its returns split it into two
/// clusters): their axes within 25 deg and either their attachments within 6 cm or each
/// centre on the other's axis line (within 2 cm or the sum of their radii) with the centres
/// within 0.4 m.
bool sameBranch(const BranchFit& a, const BranchFit& b);

/// @brief Whether two detections are pieces of one curved branch (a steep scaffold bending
/// up): one's centre inside the other's tube (within 3 cm or its radius of the axis, and 7 cm
/// of its ends) and their axes within 45 deg. The branch opposite across the trunk lies on the
/// axis line as well, but a trunk's width beyond the ends.
bool curvedPieces(const BranchFit& a, const BranchFit& b);

/// @brief Algorithm 3 step 5. Candidate points are, in the paper's way, the points of `region`
/// (trunk and primary-branch clusters) off their trunk segment's cylinder; with
/// config.ours_branch_shell, every point of the cloud in a shell around the trunk cylinders.
/// Candidates are grouped by Euclidean clustering, one cluster per branch, and a RANSAC
/// cylinder is fitted to each cluster's part within branch_fit_length of the trunk surface.
/// With config.ours_constrain_ransac a branch must leave the trunk surface: its axis points
/// away from the trunk and passes close to the trunk axis (neighbours' branches and wires
/// crossing near the trunk do not), and duplicates of one branch are merged.
/// @param index a PointIndex of `pts`
/// @param rejected when given, receives every candidate turned down
/// @param wire_directions the directions of the wires preprocessing removed (the row's): a
/// short wire piece left in the cloud runs along them; empty: any direction
std::vector<BranchFit> modelBranches(const Points& pts, const PointIndex& index,
                                     const TrunkModel& trunk, const std::vector<int>& region,
                                     const ModelerConfig& config,
                                     std::vector<RejectedBranch>* rejected = nullptr,
                                     const std::vector<Eigen::Vector3d>& wire_directions = {});

}  // namespace modeling
}  // namespace dormant_tree_modeling
