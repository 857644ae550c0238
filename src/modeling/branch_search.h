#pragma once

// The search for primary branches among the candidate clusters (Algorithm 3 step 5), private to
// the modeler: modelBranches collects the candidates, runs this search, then judges the fits
// cut off from the trunk, merges duplicates and drops sparse detections.

#include <Eigen/Core>
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "dormant_tree_modeling/modeling/branch_model.h"

namespace dormant_tree_modeling {
namespace modeling {
namespace detail {

/// Where a point sits relative to the trunk model.
struct TrunkCoords {
  int segment = -1;
  double s = 0.0;         ///< along the centreline, m
  double distance = 0.0;  ///< to the segment cylinder's axis, m
};

/// The noise bands of one tree's branch search, derived once from the trunk's noise estimate.
struct BranchBands {
  double sigma = 0.0;         ///< range noise, m
  double search_sigma = 0.0;  ///< the scatter the search's gates take, m (TrunkModel)
  double table_sigma = 0.0;   ///< the noise as the radius tables read it, m (TrunkModel)
  double scatter = 0.0;       ///< the beam's lateral scatter taken off radii, m (0: none)
  double threshold = 0.0;     ///< cylinder inlier band, m
  double inner_gap = 0.0;     ///< how far off the trunk surface candidates start, m
};

/// The candidate points of the branch search and where each sits on the trunk.
struct BranchCandidates {
  std::vector<int> index;          ///< into the modeled cloud
  std::vector<TrunkCoords> where;  ///< one per candidate
  Points pts;                      ///< the candidates' coordinates
};

/// A fit whose points start away from the trunk surface with returns filling the way there:
/// judged once every branch reaching the trunk is known.
struct CutFit {
  BranchFit fit;
  double gap = 0.0;  ///< of its nearest point from the trunk surface, m
  RejectedBranch as_rejected;
};

/// What the search reads and never changes.
struct BranchContext {
  const PointIndex& index;  ///< of the modeled cloud
  const TrunkModel& trunk;
  const ModelerConfig& config;
  const BranchBands& bands;
  const std::vector<Eigen::Vector3d>& wire_directions;
};

/// @brief The walk from a fit towards the trunk surface, in steps of CUT_WALK_STEP: from its near
/// end to where its axis passes the trunk's when it crosses the trunk at a clear angle, else
/// along its axis from its centre. Calls visit(q) for each step at most `gap` off the surface,
/// until `inner_gap` or the way's closest approach to the trunk.
/// @return false when visit stopped the walk (returned false) or the walk ran out of reach
bool walkToSurface(const Cylinder& fit, const Cylinder& seg, double inner_gap, double gap,
                   const std::function<bool(const Eigen::Vector3d&)>& visit);

/// @brief The way back to the trunk a fit's steps take, in m per step.
constexpr double CUT_WALK_STEP = 0.01;

/// @brief A candidate turned down: the centroid and count of its members (indices into pts).
RejectedBranch rejection(const Points& pts, const std::vector<int>& members, BranchRejection reason,
                         bool budget_spent = false);

/// @brief The work list of the search: clusters, the parts a fused cluster was split into, and
/// what is left of a cluster once a branch or a wire was taken out of it, within a budget of
/// such extractions (config.branches.search_budget).
class BranchSearch {
 public:
  /// @param rejected when given, receives every candidate turned down
  BranchSearch(const BranchContext& context, const BranchCandidates& candidates,
               std::vector<RejectedBranch>* rejected);

  /// @brief Searches the clusters (indices into the candidates), the last first. With
  /// fit.constrain and branches.steep_search, what was turned down is then clustered again and
  /// searched for steep branches only (searchSteep), and only then reported as turned down.
  void run(const std::vector<std::vector<int>>& clusters);

  /// @brief The fits that reach the trunk surface, in the order found.
  std::vector<BranchFit>& branches() { return branches_; }
  /// @brief The fits cut off from the trunk surface, in the order found.
  std::vector<CutFit>& cutFits() { return cut_; }

 private:
  struct Candidate {
    std::vector<int> members;  // indices into the candidates
    // Set when parted from a fused candidate along its strongest ray: that ray's direction.
    std::optional<Eigen::Vector3d> ray;
  };
  // The part of a candidate near the trunk: where diameters are measured and pruning cuts.
  struct NearPart {
    Points pts;
    std::vector<int> index;  // into the modeled cloud
    double nearest_gap = 1e300;
    int segment = 0;  // of the candidate's point nearest to the trunk surface
  };
  struct Verdict {
    BranchRejection reason;
    bool splittable;
  };
  // A candidate turned down, kept with its members until the steep search has seen them.
  struct TurnedDown {
    std::vector<int> members;  // indices into the candidates
    RejectedBranch as_rejected;
  };
  struct Direction {
    Eigen::Vector3d radial;  // from the trunk axis through the near part, level with it
    Eigen::Vector3d axis;    // the guess the fit starts from
    double max_angle;        // rad, of the fit's axis from the radial
  };

  void searchWorkList();
  void searchSteep();
  void reportTurnedDown(std::size_t steep_from);
  void examine(const Candidate& candidate);
  NearPart nearPart(const std::vector<int>& cluster, double reach) const;
  bool leadsBack(const Cylinder& fit, const Cylinder& seg, const NearPart& near) const;
  bool refitCutOff(const Candidate& candidate, const Cylinder& seg, const NearPart& near,
                   Cylinder* cyl);
  bool refitAtFork(const Candidate& candidate, const Cylinder& seg, const Direction& guess,
                   NearPart* near, Cylinder* cyl, std::vector<int>* inliers, double* wood_radius);
  std::optional<Cylinder> baseFit(const Candidate& candidate, const Cylinder& seg,
                                  const Direction& guess);
  NearPart alongLine(const NearPart& near, const Cylinder& line, const Cylinder& side_arm) const;
  double extractionReach(const Cylinder& found) const;
  std::optional<Direction> direction(const NearPart& near, const Cylinder& seg) const;
  std::optional<Cylinder> fit(const NearPart& near, const Cylinder& seg, const Direction& guess,
                              std::uint64_t seed, std::vector<int>* inliers, double* wood_radius);
  std::optional<Cylinder> outwardFit(const NearPart& part, const Cylinder& seg,
                                     const Direction& guess, std::uint64_t seed,
                                     std::vector<int>* inliers, double* wood_radius);
  std::uint64_t nextFitSeed();
  std::uint64_t nextRefitSeed();
  std::uint64_t nextCutRefitSeed();
  std::optional<Verdict> checkDirection(const Candidate& candidate, const Cylinder& fit,
                                        const Cylinder& seg, const Direction& guess,
                                        double gap) const;
  std::optional<Verdict> checkPlace(const Candidate& candidate, const Cylinder& fit,
                                    const Eigen::Vector3d& attachment) const;
  bool spansTheTrunk(const Cylinder& fit, const Cylinder& seg, const NearPart& near,
                     const std::vector<int>& inliers) const;
  bool reachesSurface(const NearPart& near) const;
  void accept(const Candidate& candidate, const NearPart& near, const Cylinder& fit,
              double wood_radius, const std::vector<int>& inliers,
              const Eigen::Vector3d& attachment, bool reaches_surface);
  void reject(const Candidate& candidate, int segment, Verdict verdict);
  bool splitAlongRay(const Candidate& candidate, const Points& cluster_pts, int segment);
  bool splitInHalves(const Candidate& candidate, const Points& cluster_pts);
  std::vector<int> searchRest(const std::vector<int>& cluster, const Cylinder& found);
  void pushParts(const std::vector<int>& rest);
  // Euclidean clusters (branches.cluster_tolerance_m, branches.min_points) of some
  // candidates, as indices into the candidates.
  std::vector<std::vector<int>> clustersOf(const std::vector<int>& members) const;
  bool budgetLeft() const;

  const BranchContext context_;  // a copy: callers pass a temporary (it holds references only)
  const BranchCandidates& candidates_;
  std::vector<RejectedBranch>* rejected_;
  std::vector<Candidate> work_;
  int extractions_ = 0;
  std::uint64_t stream_ = 0;  // of random seeds, one per k-means split and per fit
  // Of the refits at forks, apart: a refit leaves every other fit's seed as it was.
  std::uint64_t refit_stream_ = 0;
  // Of the cut-off pieces' refits along their whole length, apart for the same reason.
  std::uint64_t cut_refit_stream_ = 0;
  std::vector<BranchFit> branches_;
  std::vector<CutFit> cut_;
  std::vector<TurnedDown> turned_down_;
  // In the steep search every candidate keeps its own direction up to
  // branches.max_steep_angle_deg, and only fits steeper than branches.max_radial_angle_deg pass.
  bool steep_pass_ = false;
};

}  // namespace detail
}  // namespace modeling
}  // namespace dormant_tree_modeling
