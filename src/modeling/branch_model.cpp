#include "dormant_tree_modeling/modeling/branch_model.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <utility>

#include "branch_search.h"
#include "dormant_tree_modeling/common/parallel.h"
#include "dormant_tree_modeling/common/statistics.h"
#include "dormant_tree_modeling/modeling/noise_band.h"
#include "dormant_tree_modeling/modeling/point_index.h"

namespace dormant_tree_modeling {
namespace modeling {

namespace {

constexpr double DEG = M_PI / 180.0;
// Candidates lie this far beyond the ends of the trunk cylinders along the centreline, and
// (in the shell) this far beyond branches.fit_length_m off the trunk surface.
constexpr double SHELL_AXIAL_MARGIN = 0.05;  // m
constexpr double SHELL_OUTER_MARGIN = 0.05;  // m
// A fit cut off from the trunk surface keeps at least this much of its way back off every
// accepted fit.
constexpr double CUT_MIN_OWN_WAY = 0.03;  // m
// Detections needed before their median point count says what this tree's primaries return.
constexpr std::size_t MIN_BRANCHES_FOR_MEDIAN = 4;
// Two detections of one branch: axes within DUPLICATE_MAX_ANGLE and attachments closer than
// DUPLICATE_ATTACHMENT_GAP, or each centre within DUPLICATE_LINE_GAP (or their radii) of the
// other's axis and the centres within DUPLICATE_REACH.
constexpr double DUPLICATE_MAX_ANGLE = 25.0 * DEG;
constexpr double DUPLICATE_ATTACHMENT_GAP = 0.06;  // m
constexpr double DUPLICATE_LINE_GAP = 0.02;        // m
constexpr double DUPLICATE_REACH = 0.4;            // m
// A curved branch (a steep scaffold) fitted twice: one fit's centre inside the other's tube,
// within DUPLICATE_TUBE_RADIUS (or its radius) of its axis and DUPLICATE_TUBE_MARGIN of its
// ends, the pieces' axes within DUPLICATE_CURVED_ANGLE. The branch opposite across the trunk
// lies on the axis line too, but points the other way and lies a trunk's width beyond the ends.
constexpr double DUPLICATE_CURVED_ANGLE = 45.0 * DEG;
constexpr double DUPLICATE_TUBE_RADIUS = 0.03;  // m
constexpr double DUPLICATE_TUBE_MARGIN = 0.07;  // m

using detail::BranchBands;
using detail::BranchCandidates;
using detail::CutFit;
using detail::TrunkCoords;

TrunkCoords locate(const TrunkModel& trunk, const Eigen::Vector3d& p) {
  TrunkCoords c;
  c.s = trunk.centerline.project(p);
  c.segment = trunk.cylinderAt(c.s);
  if (c.segment >= 0)
    c.distance = axisDistance(trunk.cylinders[c.segment], p);
  return c;
}

/// Bands follow the range noise; radii lose the noise and the beam's lateral scatter.
BranchBands branchBands(const TrunkModel& trunk, const ModelerConfig& config) {
  BranchBands b;
  b.sigma = trunk.noise_sigma;
  b.table_sigma = trunk.table_sigma;
  b.search_sigma = trunk.search_sigma;
  b.scatter = config.noise.correct_bias ? trunk.scatter : 0.0;
  b.threshold = config.fit.cylinder_threshold_m;
  if (config.noise.derive_parameters)
    b.threshold = std::max(b.threshold, noiseBand(b.sigma));
  b.inner_gap = config.branches.shell ? config.branches.inner_gap_m : b.threshold;
  return b;
}

/// The candidate points: in the paper's way the points of `region` off their trunk segment's
/// cylinder; with branches.shell every point in a shell around the trunk cylinders, which
/// starts away from the trunk because near its surface the trunk's noise links every branch
/// to every other. Points flagged in `not_branches` (another column's surface) are left out.
/// Located on all cores, kept in index order.
BranchCandidates collectCandidates(const Points& pts, const TrunkModel& trunk,
                                   const std::vector<int>& region, const ModelerConfig& config,
                                   const BranchBands& bands,
                                   const std::vector<char>& not_branches) {
  const double s_lo = trunk.cylinder_ranges.front().first - SHELL_AXIAL_MARGIN;
  const double s_hi = trunk.cylinder_ranges.back().second + SHELL_AXIAL_MARGIN;
  const bool shell = config.branches.shell;
  const int n_points = static_cast<int>(shell ? pts.size() : region.size());
  std::vector<TrunkCoords> located(n_points);
  parallelFor(n_points, [&](int k) { located[k] = locate(trunk, pts[shell ? k : region[k]]); });
  BranchCandidates out;
  for (int k = 0; k < n_points; ++k) {
    const TrunkCoords& c = located[k];
    if (c.segment < 0 || c.s < s_lo || c.s > s_hi)
      continue;
    const double r = trunk.cylinders[c.segment].radius;
    if (c.distance <= r + bands.threshold)
      continue;  // on the trunk surface
    if (shell && (c.distance < r + config.branches.inner_gap_m ||
                  c.distance > r + config.branches.fit_length_m + SHELL_OUTER_MARGIN))
      continue;
    const int i = shell ? k : region[k];
    if (!not_branches.empty() && not_branches[i])
      continue;
    out.index.push_back(i);
    out.where.push_back(c);
    out.pts.push_back(pts[i]);
  }
  return out;
}

/// How much of the way from a fit to the trunk lies off every accepted fit (m): there the
/// returns are the fit's own near part, cut off by a crossing branch's extraction. A shoot's
/// way back runs inside its parent, and a piece of an accepted branch inside that branch.
double ownWayToSurface(const Cylinder& fit, const Cylinder& seg,
                       const std::vector<BranchFit>& accepted, double inner_gap, double gap,
                       double tube) {
  double own = 0.0;
  detail::walkToSurface(fit, seg, inner_gap, gap, [&](const Eigen::Vector3d& q) {
    for (const auto& b : accepted) {
      const Cylinder& c = b.cylinder;
      if (axisDistance(c, q) < c.radius + tube &&
          std::abs((q - c.center).dot(c.axis)) < 0.5 * c.length)
        return true;
    }
    own += detail::CUT_WALK_STEP;
    return true;
  });
  return own;
}

/// A fit cut off from the trunk is judged once every branch reaching the trunk is known: its
/// way back must not lie all inside them.
void keepCutOffFits(std::vector<CutFit>& cut, const TrunkModel& trunk, const BranchBands& bands,
                    std::vector<BranchFit>& branches, std::vector<RejectedBranch>* rejected) {
  for (auto& c : cut) {
    const Cylinder& seg = trunk.cylinders[c.fit.trunk_segment];
    const double own = ownWayToSurface(c.fit.cylinder, seg, branches, bands.inner_gap, c.gap,
                                       c.fit.cylinder.radius + bands.threshold);
    if (own < CUT_MIN_OWN_WAY) {
      if (rejected)
        rejected->push_back(c.as_rejected);
      continue;
    }
    branches.push_back(std::move(c.fit));
  }
}

/// Keeps the fits not marked in drop; the others are reported as turned down for reason.
void removeMarked(std::vector<BranchFit>& branches, const std::vector<char>& drop,
                  BranchRejection reason, std::vector<RejectedBranch>* rejected) {
  std::vector<BranchFit> kept;
  for (std::size_t i = 0; i < branches.size(); ++i) {
    if (!drop[i]) {
      kept.push_back(std::move(branches[i]));
    } else if (rejected) {
      RejectedBranch r;
      r.centroid = branches[i].cylinder.center;
      r.points = static_cast<int>(branches[i].inliers.size());
      r.reason = reason;
      rejected->push_back(r);
    }
  }
  branches.swap(kept);
}

/// One branch split into two clusters (a gap in its returns) appears twice: keep the one that
/// reaches the trunk surface, else the larger. Of two pieces of a curved branch the longer
/// one's axis is the better determined (the other piece, whichever reaches the trunk, is short
/// and bent away from the branch).
void mergeDuplicates(std::vector<BranchFit>& branches, bool merge_curved,
                     std::vector<RejectedBranch>* rejected) {
  std::vector<char> drop(branches.size(), 0);
  for (std::size_t i = 0; i < branches.size(); ++i) {
    for (std::size_t k = i + 1; k < branches.size(); ++k) {
      if (drop[i] || drop[k])
        continue;
      const auto& a = branches[i];
      const auto& b = branches[k];
      const bool curved = merge_curved && curvedPieces(a, b);
      if (!curved && !sameBranch(a, b))
        continue;
      const bool keep_a = curved ? a.cylinder.length >= b.cylinder.length
                          : a.reaches_surface != b.reaches_surface
                              ? a.reaches_surface
                              : a.inliers.size() >= b.inliers.size();
      drop[keep_a ? k : i] = 1;
    }
  }
  removeMarked(branches, drop, BranchRejection::DUPLICATE, rejected);
}

/// The primaries of one tree near its trunk return comparable numbers of points; a detection
/// with a small fraction (min_relative_points) of the usual is a shoot on a primary, the tip of
/// a neighbour's branch reaching in or a streak of mixed pixels.
void dropSparse(std::vector<BranchFit>& branches, double min_relative_points,
                std::vector<RejectedBranch>* rejected) {
  if (min_relative_points <= 0.0 || branches.size() < MIN_BRANCHES_FOR_MEDIAN)
    return;
  std::vector<double> counts;
  for (const auto& b : branches)
    counts.push_back(static_cast<double>(b.inliers.size()));
  const double floor = min_relative_points * median(std::move(counts));
  std::vector<char> drop(branches.size(), 0);
  for (std::size_t i = 0; i < branches.size(); ++i)
    drop[i] = static_cast<double>(branches[i].inliers.size()) < floor;
  removeMarked(branches, drop, BranchRejection::FEW_POINTS_FOR_THIS_TREE, rejected);
}

}  // namespace

const char* branchRejectionText(BranchRejection reason) {
  switch (reason) {
    case BranchRejection::TOO_FEW_POINTS:
      return "too few points";
    case BranchRejection::NO_FIT:
      return "no fit";
    case BranchRejection::OFF_ITS_RAY:
      return "off its ray";
    case BranchRejection::NOT_RADIAL:
      return "not radial";
    case BranchRejection::POINTS_DOWN:
      return "points down";
    case BranchRejection::THICKER_THAN_THE_TRUNK:
      return "thicker than the trunk";
    case BranchRejection::MISSES_THE_TRUNK:
      return "misses the trunk";
    case BranchRejection::SPANS_THE_TRUNK:
      return "spans the trunk";
    case BranchRejection::NOT_AT_THE_SURFACE:
      return "not at the surface";
    case BranchRejection::TOO_SHORT:
      return "too short";
    case BranchRejection::TOO_LOW:
      return "too low";
    case BranchRejection::WIRE:
      return "a wire";
    case BranchRejection::DUPLICATE:
      return "duplicate";
    case BranchRejection::FEW_POINTS_FOR_THIS_TREE:
      return "few points for this tree";
    case BranchRejection::REMAINDER_NOT_SEARCHED:
      return "remainder not searched";
  }
  return "unknown";
}

std::string RejectedBranch::text() const {
  std::string t = branchRejectionText(reason);
  if (budget_spent)
    t += " (search budget spent)";
  return t;
}

bool curvedPieces(const BranchFit& a, const BranchFit& b) {
  const Cylinder &ca = a.cylinder, &cb = b.cylinder;
  const double angle = std::acos(std::clamp(ca.axis.dot(cb.axis), -1.0, 1.0));
  if (angle >= DUPLICATE_CURVED_ANGLE)
    return false;
  const auto inTube = [](const Cylinder& c, const Eigen::Vector3d& p) {
    return std::abs((p - c.center).dot(c.axis)) <= 0.5 * c.length + DUPLICATE_TUBE_MARGIN &&
           axisDistance(c, p) <= std::max(DUPLICATE_TUBE_RADIUS, c.radius);
  };
  return inTube(ca, cb.center) || inTube(cb, ca.center);
}

bool sameBranch(const BranchFit& a, const BranchFit& b) {
  const Cylinder &ca = a.cylinder, &cb = b.cylinder;
  const double angle = std::acos(std::clamp(ca.axis.dot(cb.axis), -1.0, 1.0));
  if (angle >= DUPLICATE_MAX_ANGLE)
    return false;
  if ((a.attachment - b.attachment).norm() < DUPLICATE_ATTACHMENT_GAP)
    return true;
  // Pieces of one branch lie on one line: on a steep branch the attachment (where its axis
  // passes the trunk's) is ill-conditioned, and two pieces of it attach centimetres apart.
  const double off_line = std::max(axisDistance(ca, cb.center), axisDistance(cb, ca.center));
  return off_line < std::max(DUPLICATE_LINE_GAP, ca.radius + cb.radius) &&
         (ca.center - cb.center).norm() < DUPLICATE_REACH;
}

std::vector<int> branchBasePoints(const Points& pts, const std::vector<int>& region,
                                  const TrunkModel& trunk, const std::vector<BranchFit>& branches,
                                  double band) {
  struct Base {
    Eigen::Vector3d from, to;  // where the way from the attachment leaves the trunk; near end
    double radius;
    double z_min, z_max;  // of the tube
  };
  std::vector<Base> bases;
  for (const auto& b : branches) {
    const Eigen::Vector3d near_end = b.cylinder.center - 0.5 * b.cylinder.length * b.cylinder.axis;
    const Eigen::Vector3d way = near_end - b.attachment;
    const double trunk_radius = 0.5 * trunk.diameterAt(trunk.centerline.project(b.attachment));
    const Eigen::Vector3d from =
        way.norm() > trunk_radius ? Eigen::Vector3d(b.attachment + trunk_radius * way.normalized())
                                  : near_end;
    const double r = b.cylinder.radius;
    bases.push_back({from, near_end, r, std::min(from.z(), near_end.z()) - r,
                     std::max(from.z(), near_end.z()) + r});
  }
  std::vector<int> out;
  for (const int k : region) {
    const Eigen::Vector3d& p = pts[k];
    double d = 0.0;
    const double s = trunk.centerline.project(p, &d);
    const double off_trunk = d - 0.5 * trunk.diameterAt(s);
    if (off_trunk <= band)
      continue;
    for (const auto& b : bases) {
      if (p.z() < b.z_min - off_trunk || p.z() > b.z_max + off_trunk)
        continue;
      if (std::abs(segmentDistance(p, b.from, b.to) - b.radius) < off_trunk) {
        out.push_back(k);
        break;
      }
    }
  }
  return out;
}

std::vector<BranchFit> modelBranches(const Points& pts, const PointIndex& index,
                                     const TrunkModel& trunk, const std::vector<int>& region,
                                     const ModelerConfig& config,
                                     std::vector<RejectedBranch>* rejected,
                                     const std::vector<Eigen::Vector3d>& wire_directions,
                                     const std::vector<char>& not_branches) {
  if (trunk.cylinders.empty())
    return {};
  const BranchBands bands = branchBands(trunk, config);
  const BranchCandidates candidates =
      collectCandidates(pts, trunk, region, config, bands, not_branches);
  const auto clusters = euclideanClusters(candidates.pts, config.branches.cluster_tolerance_m,
                                          config.branches.min_points);
  detail::BranchSearch search({index, trunk, config, bands, wire_directions}, candidates, rejected);
  search.run(clusters);
  std::vector<BranchFit> branches = std::move(search.branches());
  keepCutOffFits(search.cutFits(), trunk, bands, branches, rejected);
  if (config.fit.constrain)
    mergeDuplicates(branches, config.branches.merge_curved, rejected);
  dropSparse(branches, config.branches.min_relative_points, rejected);
  return branches;
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
