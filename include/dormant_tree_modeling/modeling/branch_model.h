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

/// @brief Why a branch candidate was turned down.
enum class BranchRejection {
  TOO_FEW_POINTS,            ///< fewer than branches.min_points within branches.fit_length_m
  NO_FIT,                    ///< no cylinder fits its near part
  OFF_ITS_RAY,               ///< parted along a ray, its fit leaves that ray
  NOT_RADIAL,                ///< the fit does not point away from the trunk
  POINTS_DOWN,               ///< the fit dives below branches.min_elevation_deg
  THICKER_THAN_THE_TRUNK,    ///< wider than branches.max_diameter_ratio of its trunk segment
  MISSES_THE_TRUNK,          ///< the fit's axis passes the trunk axis beyond branches.axis_gap_m
  SPANS_THE_TRUNK,           ///< the fit's points lie on both sides of the trunk
  NOT_AT_THE_SURFACE,        ///< its points start away from the trunk with air between
  TOO_SHORT,                 ///< shorter than branches.min_length_m
  TOO_LOW,                   ///< attached below branches.min_height_m
  WIRE,                      ///< a trellis wire's points (taken out of the candidate)
  DUPLICATE,                 ///< a second detection of a branch already kept
  FEW_POINTS_FOR_THIS_TREE,  ///< under branches.min_relative_points of the tree's median
  REMAINDER_NOT_SEARCHED,    ///< what an extraction left, with the search budget spent
};

/// @brief The words for a reason, as logs and `tree_model -v` print them ("too few points",
/// "no fit", "off its ray", "not radial", "points down", "thicker than the trunk", "misses the
/// trunk", "spans the trunk", "not at the surface", "too short", "too low", "a wire", "duplicate",
/// "few points for this tree", "remainder not searched").
const char* branchRejectionText(BranchRejection reason);

/// @brief A branch candidate that was turned down, and why (for diagnostics).
struct RejectedBranch {
  Eigen::Vector3d centroid = Eigen::Vector3d::Zero();  ///< of the candidate's points
  int points = 0;
  BranchRejection reason = BranchRejection::NO_FIT;
  /// It could have been split (or searched) but the search budget was spent.
  bool budget_spent = false;

  /// @brief The reason's words, with " (search budget spent)" when budget_spent.
  std::string text() const;
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

/// @brief The points of `region` beyond the trunk's surface band and nearer a found branch's
/// surface than the trunk's: each branch is a tube of its radius about the way from its
/// attachment to its fit's near end, from where that way leaves the trunk; the trunk is a tube
/// of trunk.diameterAt() about its centreline. These are the branch bases a slice through a
/// whorl takes in: they widen its circle.
/// @param region indices into `pts`
/// @param band how far off the trunk's surface (m) a point may lie and stay the trunk's
/// (trunkSurfaceBand): the trunk's own returns pushed outward by the noise
/// @return a subset of `region`, in its order
std::vector<int> branchBasePoints(const Points& pts, const std::vector<int>& region,
                                  const TrunkModel& trunk, const std::vector<BranchFit>& branches,
                                  double band);

/// @brief Algorithm 3 step 5. Candidate points are, in the paper's way, the points of `region`
/// (trunk and primary-branch clusters) off their trunk segment's cylinder; with
/// config.branches.shell, every point of the cloud in a shell around the trunk cylinders.
/// Candidates are grouped by Euclidean clustering, one cluster per branch, and a RANSAC
/// cylinder is fitted to each cluster's part within branches.fit_length_m of the trunk surface.
/// With config.fit.constrain a branch must leave the trunk surface: its axis points
/// away from the trunk and passes close to the trunk axis (neighbours' branches and wires
/// crossing near the trunk do not), and duplicates of one branch are merged.
/// @param index a PointIndex of `pts`
/// @param rejected when given, receives every candidate turned down
/// @param wire_directions the directions of the wires preprocessing removed (the row's): a
/// short wire piece left in the cloud runs along them; empty: any direction
/// @param not_branches per point of `pts` (or empty): flagged points are no candidates (the
/// surfaces of other upright columns: pointsOnColumns)
std::vector<BranchFit> modelBranches(const Points& pts, const PointIndex& index,
                                     const TrunkModel& trunk, const std::vector<int>& region,
                                     const ModelerConfig& config,
                                     std::vector<RejectedBranch>* rejected = nullptr,
                                     const std::vector<Eigen::Vector3d>& wire_directions = {},
                                     const std::vector<char>& not_branches = {});

}  // namespace modeling
}  // namespace dormant_tree_modeling
