#include "branch_search.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <utility>

#include "dormant_tree_modeling/modeling/branch_rays.h"
#include "dormant_tree_modeling/modeling/noise_band.h"
#include "dormant_tree_modeling/modeling/point_index.h"
#include "dormant_tree_modeling/modeling/tree_model.h"

namespace dormant_tree_modeling {
namespace modeling {
namespace detail {

namespace {

constexpr double DEG = M_PI / 180.0;
constexpr double SURFACE_CONTACT = 0.05;  // m beyond inner_gap that still touches the trunk
// The paper's search: the RANSAC axis strays up to this far from the guess, and a branch may be
// as wide as this.
constexpr double PAPER_MAX_AXIS_DEVIATION = 35.0 * DEG;
constexpr double PAPER_MAX_BRANCH_RADIUS = 0.3;  // m
// Ours: the axis stays closer to the guess, and a branch no wider than its trunk segment.
constexpr double MAX_AXIS_DEVIATION = 30.0 * DEG;
constexpr int AXIS_CANDIDATES = 8;
// A fit wider across the trunk than along it by this share of its length is judged by its
// azimuth (sideways or not); a near-vertical fit is not.
constexpr double MIN_ACROSS_SHARE = 0.3;
// Of a fit's inliers, at most this share may lie behind the trunk, past where the candidates
// start (spansTheTrunk). Fits across a fused crown had 27-44 %; kept primaries at most 4 %.
constexpr double MAX_SHARE_BEHIND_THE_TRUNK = 0.15;
// A candidate this many times branches.min_points and more may be split when it fits no branch;
// a remainder this many times branches.min_points and more is searched again.
constexpr int SPLIT_MIN_SIZE = 4;
constexpr int REMAINDER_MIN_SIZE = 2;
// A candidate of this many times branches.min_points whose fit is too short is split and retried.
constexpr int SHORT_SPLIT = 12;
constexpr int HALVES_ITERATIONS = 20;  // of the k-means that halves a fused candidate
// A found line's points: within its radius, the noise band and this margin of its axis.
constexpr double EXTRACTION_MARGIN = 0.005;  // m
constexpr double STEEP_ELONGATION = 16.0;    // variance ratio (4:1 in length) of a directed cluster
// A candidate parted along a ray is a branch along it: its fit stays within this of the ray.
constexpr double RAY_AGREEMENT = 20.0 * DEG;
// Its points: within the noise band (at least RAY_MIN_BAND) plus RAY_TUBE_RADIUS (a thin
// branch's radius with a margin) of the ray.
constexpr double RAY_MIN_BAND = 0.01;     // m
constexpr double RAY_TUBE_RADIUS = 0.01;  // m
// A fit cut off from the trunk surface (branches.keep_cut_off) needs returns on its way back to
// the trunk: at each step this share of the returns around the fit's centre, at least
// CUT_FILL_MIN_POINTS.
constexpr double CUT_WALK_REACH = 1.0;  // m, beyond any fit's way back
constexpr double CUT_FILL_SHARE = 0.2;
constexpr int CUT_FILL_MIN_POINTS = 3;
// A fit crossing the trunk at this angle or more meets it at a well-placed attachment (an error
// across the fit's axis moves it no more along the trunk): its way back runs from its near end to
// there, not on along its axis, whose direction error a 0.2 m piece turns into 1-2 cm at the
// trunk.
constexpr double WAY_MIN_TRUNK_ANGLE = 45.0 * DEG;
// A cut-off piece's near part may hold what a crossing branch's extraction left of it (the
// crossing branch's own returns beside it): its fit then turns from the branch by 5-10 deg.
// The line through the whole piece replaces it when it turns by no more than this.
constexpr double CUT_REFIT_MAX_TURN = 15.0 * DEG;
// Seeds: per candidate, from the modeler's seed and a running stream.
constexpr std::uint64_t HALVES_SEED_FACTOR = 7757ULL;
constexpr std::uint64_t FIT_SEED_FACTOR = 15485863ULL;
constexpr std::uint64_t REFIT_STREAM_START = 1ULL << 32;      // past any tree's fits
constexpr std::uint64_t CUT_REFIT_STREAM_START = 2ULL << 32;  // past any tree's refits
// A primary's axis passes through its trunk: a fit whose axis passes more than FORK_AXIS_GAP
// outside the trunk surface followed a side arm forking off the branch (a secondary, a shoot at
// its tip), which leaves the branch at an angle. 96 % of matched primaries pass within it,
// fits along side arms mostly 25-70 mm off. Between lines near parallel the gap says
// little: fits within FORK_MIN_TRUNK_ANGLE of the trunk axis (steep scaffolds) are left alone.
constexpr double FORK_AXIS_GAP = 0.02;  // m
constexpr double FORK_MIN_TRUNK_ANGLE = 30.0 * DEG;
// The branch before the fork: the candidate's points within this share of branches.fit_length_m
// off the trunk surface. The refit along it turns from the side arm's fit by at most
// FORK_MAX_TURN (a fork's arms part by less; more is another branch).
constexpr double FORK_BASE_SHARE = 0.5;
constexpr double FORK_MAX_TURN = 45.0 * DEG;

// A trellis wire: thin, near level, and seen again beyond the trunk on its line. The radius is
// the fit's corrected spread, which a wire thinner than the calibration rig's thinnest rod is
// not corrected down to: 4 mm wires (the thickest our orchard generator strings, as heavy
// high-tensile trellis wire is) fit at up to 5.3 mm under our sensor model, and the bound
// leaves a third more for a wider beam. The far-side test tells a wire from a branch; the
// bound only spares thick branches that test.
constexpr double MAX_WIRE_RADIUS = 0.007;  // m
constexpr double MAX_WIRE_TILT = 15.0 * DEG;
constexpr double MAX_WIRE_CROSSING = 15.0 * DEG;  // from the row's wires
constexpr double WIRE_STEP = 0.02;                // m along the far side
constexpr double WIRE_FAR_FROM = 0.05;            // m past the trunk surface
constexpr double WIRE_FAR_TO = 0.4;               // m past the trunk surface
constexpr double WIRE_TOLERANCE = 0.008;          // m plus the noise, around each step
constexpr double WIRE_OCCUPIED_SHARE = 0.8;       // of the steps that hold a return

/// The widest branch a constrained fit takes: no wider than its trunk segment.
double maxBranchRadius(const Cylinder& seg) {
  return std::max(MIN_BRANCH_RADIUS_M * 2, seg.radius);
}

double angleBetween(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::clamp(a.dot(b), -1.0, 1.0));
}

/// The fit's heading seen along the trunk (a unit vector), when the fit runs across the trunk
/// by more than MIN_ACROSS_SHARE of its length; a near-vertical fit has none.
std::optional<Eigen::Vector3d> headingAcrossTheTrunk(const Cylinder& fit, const Cylinder& seg) {
  const Eigen::Vector3d across = fit.axis - fit.axis.dot(seg.axis) * seg.axis;
  if (across.norm() <= MIN_ACROSS_SHARE)
    return std::nullopt;
  return across.normalized();
}

/// Closest points between two lines p + t u and q + s v: returns the distance between the
/// lines and, in on_second, the point on the second.
double lineGap(const Eigen::Vector3d& p, const Eigen::Vector3d& u, const Eigen::Vector3d& q,
               const Eigen::Vector3d& v, Eigen::Vector3d* on_second) {
  const Eigen::Vector3d w = p - q;
  const double a = u.dot(u), b = u.dot(v), c = v.dot(v), d = u.dot(w), e = v.dot(w);
  const double den = a * c - b * b;
  double t = 0.0, s = 0.0;
  if (std::abs(den) > 1e-12) {
    t = (b * e - c * d) / den;
    s = (a * e - b * d) / den;
  } else {
    s = e / c;
  }
  const Eigen::Vector3d x = p + t * u, y = q + s * v;
  if (on_second)
    *on_second = y;
  return (x - y).norm();
}

/// How far a fit's axis passes outside the trunk segment's surface (m; negative: through it).
double axisGapOutside(const Cylinder& fit, const Cylinder& seg) {
  return lineGap(fit.center, fit.axis, seg.center, seg.axis, nullptr) - seg.radius;
}

/// Whether a fit's axis misses the trunk as a side arm's does (FORK_AXIS_GAP).
bool missesLikeASideArm(const Cylinder& fit, const Cylinder& seg) {
  return lineAngle(fit.axis, seg.axis) > FORK_MIN_TRUNK_ANGLE &&
         axisGapOutside(fit, seg) > FORK_AXIS_GAP;
}

/// Whether a fit's axis leads into the trunk as a primary's does, at a clear angle to it.
bool leadsIntoTheTrunk(const Cylinder& fit, const Cylinder& seg) {
  return lineAngle(fit.axis, seg.axis) > FORK_MIN_TRUNK_ANGLE &&
         axisGapOutside(fit, seg) <= FORK_AXIS_GAP;
}

/// Whether a fit runs along the row's wires (any direction when none were found).
bool alongTheWires(const Cylinder& c, const std::vector<Eigen::Vector3d>& wire_directions) {
  if (wire_directions.empty())
    return true;
  const Eigen::Vector2d level = c.axis.head<2>().normalized();
  bool parallel = false;
  for (const auto& w : wire_directions) {
    parallel =
        parallel || std::abs(level.dot(w.head<2>().normalized())) >= std::cos(MAX_WIRE_CROSSING);
  }
  return parallel;
}

/// A thin horizontal line that continues straight through the trunk and out of its other
/// side is a trellis wire (a branch ends at the trunk); preprocessing misses wires that run
/// shorter than wire_min_length inside a tight crop. The wires of a row are parallel: when
/// preprocessing found some, a piece crossing them is no wire (a branch and the one opposite
/// it continue each other's line as well).
bool looksLikeWire(const Cylinder& c, const Cylinder& trunk_segment, const PointIndex& index,
                   double sigma, const std::vector<Eigen::Vector3d>& wire_directions) {
  if (c.radius > MAX_WIRE_RADIUS || std::abs(c.axis.z()) > std::sin(MAX_WIRE_TILT))
    return false;
  if (!alongTheWires(c, wire_directions))
    return false;
  // Walk the axis backwards through the trunk and sample its far side.
  Eigen::Vector3d through;
  lineGap(c.center, c.axis, trunk_segment.center, trunk_segment.axis, &through);
  const double t_trunk = (through - c.center).dot(c.axis);
  const double tolerance = WIRE_TOLERANCE + sigma;
  int samples = 0, occupied = 0;
  for (double d = trunk_segment.radius + WIRE_FAR_FROM; d <= trunk_segment.radius + WIRE_FAR_TO;
       d += WIRE_STEP) {
    const Eigen::Vector3d q = c.center + (t_trunk - d) * c.axis;
    ++samples;
    occupied += index.countWithin(q, tolerance, 1) > 0;
  }
  return samples > 0 && occupied >= WIRE_OCCUPIED_SHARE * samples;
}

/// The way from a fit back to the trunk, as a line walked from its centre against its axis:
/// for a fit crossing the trunk at WAY_MIN_TRUNK_ANGLE or more, from the fit's near end to where
/// its axis passes the trunk's (the attachment); for a steeper one, whose attachment is
/// ill-placed along the trunk, its own axis.
Cylinder wayBack(const Cylinder& fit, const Cylinder& seg) {
  if (lineAngle(fit.axis, seg.axis) < WAY_MIN_TRUNK_ANGLE)
    return fit;
  Eigen::Vector3d attachment;
  lineGap(fit.center, fit.axis, seg.center, seg.axis, &attachment);
  Cylinder way = fit;
  way.center = fit.center - 0.5 * fit.length * fit.axis;
  const Eigen::Vector3d out = way.center - attachment;
  if (out.norm() > 0.0)
    way.axis = out.normalized();
  return way;
}

/// Whether returns fill a fit's way back (wayBack) from inner_gap off the trunk surface out to
/// the fit's nearest point (gap), at CUT_FILL_SHARE of the density around the fit's centre: a
/// branch crossing another near the trunk is cut in two by the other's extraction, and its outer
/// part starts away from the surface, while a neighbour's tip or a shoot in the shell has air
/// between it and the trunk.
bool filledToSurface(const Cylinder& fit, const Cylinder& seg, const PointIndex& index,
                     double inner_gap, double gap, double tube) {
  const double own = static_cast<double>(index.within(fit.center, tube).size());
  const int needed =
      std::max(CUT_FILL_MIN_POINTS, static_cast<int>(std::ceil(CUT_FILL_SHARE * own)));
  return walkToSurface(fit, seg, inner_gap, gap, [&](const Eigen::Vector3d& q) {
    return index.countWithin(q, tube, needed) >= needed;
  });
}

}  // namespace

bool walkToSurface(const Cylinder& fit, const Cylinder& seg, double inner_gap, double gap,
                   const std::function<bool(const Eigen::Vector3d&)>& visit) {
  const Cylinder way = wayBack(fit, seg);
  double last = 1e300;
  for (double t = 0.0; t < CUT_WALK_REACH; t += CUT_WALK_STEP) {
    const Eigen::Vector3d q = way.center - t * way.axis;
    const double d = axisDistance(seg, q) - seg.radius;
    if (d < inner_gap || d > last)
      return true;
    last = d;
    if (d <= gap && !visit(q))
      return false;
  }
  return false;
}

RejectedBranch rejection(const Points& pts, const std::vector<int>& members, BranchRejection reason,
                         bool budget_spent) {
  RejectedBranch r;
  for (const int k : members)
    r.centroid += pts[k];
  r.centroid /= static_cast<double>(members.size());
  r.points = static_cast<int>(members.size());
  r.reason = reason;
  r.budget_spent = budget_spent;
  return r;
}

BranchSearch::BranchSearch(const BranchContext& context, const BranchCandidates& candidates,
                           std::vector<RejectedBranch>* rejected)
    : context_(context), candidates_(candidates), rejected_(rejected) {}

void BranchSearch::run(const std::vector<std::vector<int>>& clusters) {
  for (auto it = clusters.rbegin(); it != clusters.rend(); ++it)
    work_.push_back({*it, std::nullopt});
  searchWorkList();
  const std::size_t steep_from = branches_.size();
  const ModelerConfig& config = context_.config;
  if (config.fit.constrain && config.branches.steep_search)
    searchSteep();
  reportTurnedDown(steep_from);
}

void BranchSearch::searchWorkList() {
  while (!work_.empty()) {
    const Candidate candidate = std::move(work_.back());
    work_.pop_back();
    examine(candidate);
  }
}

/// Steep scaffolds (60-75 deg from the radial) leave the trunk side by side and fuse into
/// clusters that are not one long directed line, so the first search judges them by the
/// radial bound; their halves then fail too. Once every other branch is out, what was turned
/// down is clustered again, the fused pieces whole, and searched for steep fits alone: a
/// shallower fit was judged already, and a steep one can no longer take another branch's
/// points.
void BranchSearch::searchSteep() {
  std::vector<int> left;
  for (const TurnedDown& t : turned_down_)
    left.insert(left.end(), t.members.begin(), t.members.end());
  std::sort(left.begin(), left.end());
  left.erase(std::unique(left.begin(), left.end()), left.end());
  auto clusters = clustersOf(left);
  steep_pass_ = true;
  for (auto it = clusters.rbegin(); it != clusters.rend(); ++it)
    work_.push_back({std::move(*it), std::nullopt});
  searchWorkList();
  steep_pass_ = false;
}

/// Every candidate turned down is reported, but for one that gave most of its points to a
/// steep branch.
void BranchSearch::reportTurnedDown(std::size_t steep_from) {
  if (!rejected_)
    return;
  std::vector<int> taken;
  for (std::size_t i = steep_from; i < branches_.size(); ++i)
    taken.insert(taken.end(), branches_[i].inliers.begin(), branches_[i].inliers.end());
  std::sort(taken.begin(), taken.end());
  for (const TurnedDown& t : turned_down_) {
    const auto in_steep = std::count_if(t.members.begin(), t.members.end(), [&](int k) {
      return std::binary_search(taken.begin(), taken.end(), candidates_.index[k]);
    });
    if (2 * in_steep <= static_cast<std::ptrdiff_t>(t.members.size()))
      rejected_->push_back(t.as_rejected);
  }
}

bool BranchSearch::budgetLeft() const {
  return extractions_ < context_.config.branches.search_budget;
}

/// One candidate: fit a cylinder to its near part, check it is a primary (else split or turn
/// the candidate down), take a wire's points out, keep a branch and search what is left.
void BranchSearch::examine(const Candidate& candidate) {
  const ModelerConfig& config = context_.config;
  NearPart near = nearPart(candidate.members, config.branches.fit_length_m);
  if (static_cast<int>(near.pts.size()) < config.branches.min_points)
    return reject(candidate, near.segment, {BranchRejection::TOO_FEW_POINTS, false});
  const Cylinder& seg = context_.trunk.cylinders[near.segment];
  const auto guess = direction(near, seg);
  if (!guess)
    return reject(candidate, near.segment, {BranchRejection::NO_FIT, true});
  std::vector<int> inliers;
  double wood_radius = 0.0;
  auto cyl = outwardFit(near, seg, *guess, nextFitSeed(), &inliers, &wood_radius);
  if (!cyl)
    return reject(candidate, near.segment, {BranchRejection::NO_FIT, true});
  if (config.fit.constrain && missesLikeASideArm(*cyl, seg))
    refitAtFork(candidate, seg, *guess, &near, &*cyl, &inliers, &wood_radius);
  const bool cut_off = !reachesSurface(near);
  const bool leads_back = config.fit.constrain && config.branches.keep_cut_off && cut_off &&
                          refitCutOff(candidate, seg, near, &*cyl);
  Eigen::Vector3d attachment;
  const double gap = lineGap(cyl->center, cyl->axis, seg.center, seg.axis, &attachment);
  bool reaches_surface = true;
  if (config.fit.constrain) {
    if (auto verdict = checkDirection(candidate, *cyl, seg, *guess, gap))
      return reject(candidate, near.segment, *verdict);
    if (spansTheTrunk(*cyl, seg, near, inliers))
      return reject(candidate, near.segment, {BranchRejection::SPANS_THE_TRUNK, true});
    reaches_surface = !cut_off;
    // A branch crossing this one near the trunk may have taken its near part out with it;
    // its way back then leads into the trunk, which a side arm's does not.
    if (cut_off && !leads_back)
      return reject(candidate, near.segment, {BranchRejection::NOT_AT_THE_SURFACE, true});
    if (auto verdict = checkPlace(candidate, *cyl, attachment))
      return reject(candidate, near.segment, *verdict);
  }
  if (config.preprocess.remove_clutter &&
      looksLikeWire(*cyl, seg, context_.index, context_.bands.search_sigma,
                    context_.wire_directions)) {
    // A wire passing close to a branch joins its cluster: the wire's points go, the rest is
    // looked at again.
    const std::vector<int> wire = searchRest(candidate.members, *cyl);
    if (rejected_ && !wire.empty())
      rejected_->push_back(rejection(candidates_.pts, wire, BranchRejection::WIRE));
    return;
  }
  accept(candidate, near, *cyl, wood_radius, inliers, attachment, reaches_surface);
}

/// Whether a cut-off fit's way back leads into the trunk (not past it as a side arm's does) with
/// returns all along it (filledToSurface).
bool BranchSearch::leadsBack(const Cylinder& fit, const Cylinder& seg, const NearPart& near) const {
  return !missesLikeASideArm(fit, seg) &&
         filledToSurface(fit, seg, context_.index, context_.bands.inner_gap, near.nearest_gap,
                         fit.radius + context_.bands.threshold);
}

/// A branch crossing another near the trunk cuts it in two by its extraction, and the outer
/// piece's near part may keep returns of the crossing branch at its inner end. Its fit then turns
/// from the branch: it misses the trunk like a side arm's, or its way back leaves the branch's
/// returns. The line through the whole piece (a thin-cylinder fit to all its points, which a few
/// of the crossing branch's returns do not turn) is the branch's: when the near part's fit does
/// not lead back into the trunk and that line, within CUT_REFIT_MAX_TURN of it, does, the line
/// replaces its axis. The radius stays the near part's. Returns whether the fit, as it now
/// stands, leads back (leadsBack), which the surface check then reads.
bool BranchSearch::refitCutOff(const Candidate& candidate, const Cylinder& seg,
                               const NearPart& near, Cylinder* cyl) {
  if (leadsBack(*cyl, seg, near))
    return true;
  Points piece;
  for (const int k : candidate.members)
    piece.push_back(candidates_.pts[k]);
  const auto whole = fitThinCylinder(piece, cyl->axis, context_.bands.sigma, 0.0,
                                     maxBranchRadius(seg), nextCutRefitSeed());
  if (!whole)
    return false;
  Cylinder line = *cyl;
  line.axis = whole->axis.dot(cyl->axis) < 0.0 ? -whole->axis : whole->axis;
  line.center = whole->center + (cyl->center - whole->center).dot(line.axis) * line.axis;
  if (lineAngle(line.axis, cyl->axis) > CUT_REFIT_MAX_TURN || !leadsBack(line, seg, near))
    return false;
  *cyl = line;
  return true;
}

/// A fit along a side arm forking off a branch (missesLikeASideArm) is replaced by a fit along
/// the branch: the line the branch takes before the fork (baseFit), and the near part's points
/// on that line fitted again. The side arm's points stay in the candidate, searched again once
/// the branch is taken out. Returns whether the fit was replaced: not when the branch's fit
/// would not lead into the trunk or turns from the first by more than FORK_MAX_TURN.
bool BranchSearch::refitAtFork(const Candidate& candidate, const Cylinder& seg,
                               const Direction& guess, NearPart* near, Cylinder* cyl,
                               std::vector<int>* inliers, double* wood_radius) {
  const auto base = baseFit(candidate, seg, guess);
  if (!base)
    return false;
  NearPart along = alongLine(*near, *base, *cyl);
  if (static_cast<int>(along.pts.size()) < context_.config.branches.min_points)
    return false;
  Direction from_base = guess;
  from_base.axis = base->axis;
  std::vector<int> in;
  double wood = 0.0;
  const auto refit = outwardFit(along, seg, from_base, nextRefitSeed(), &in, &wood);
  if (!refit || !leadsIntoTheTrunk(*refit, seg) ||
      lineAngle(refit->axis, cyl->axis) > FORK_MAX_TURN)
    return false;
  *near = std::move(along);
  *cyl = *refit;
  *inliers = std::move(in);
  *wood_radius = wood;
  return true;
}

/// The fit to the candidate's part before a fork (FORK_BASE_SHARE of the fit length), when its
/// axis passes through the trunk.
std::optional<Cylinder> BranchSearch::baseFit(const Candidate& candidate, const Cylinder& seg,
                                              const Direction& guess) {
  const ModelerConfig& config = context_.config;
  const NearPart base = nearPart(candidate.members, FORK_BASE_SHARE * config.branches.fit_length_m);
  if (static_cast<int>(base.pts.size()) < config.branches.min_points)
    return std::nullopt;
  std::vector<int> in;
  double wood = 0.0;
  auto b = outwardFit(base, seg, guess, nextRefitSeed(), &in, &wood);
  if (b && !leadsIntoTheTrunk(*b, seg))
    return std::nullopt;
  return b;
}

/// The near part's points on a found line (extractionReach) and nearer to it than to the side
/// arm's: by the fork both lines hold them.
BranchSearch::NearPart BranchSearch::alongLine(const NearPart& near, const Cylinder& line,
                                               const Cylinder& side_arm) const {
  NearPart along;
  along.segment = near.segment;
  along.nearest_gap = near.nearest_gap;
  const double reach = extractionReach(line);
  for (std::size_t i = 0; i < near.pts.size(); ++i) {
    const double d = axisDistance(line, near.pts[i]);
    if (d <= reach && d < axisDistance(side_arm, near.pts[i])) {
      along.pts.push_back(near.pts[i]);
      along.index.push_back(near.index[i]);
    }
  }
  return along;
}

/// How far from a found line's axis its points lie: its radius (what its points spread over),
/// the noise band and a margin.
double BranchSearch::extractionReach(const Cylinder& found) const {
  const BranchBands& bands = context_.bands;
  return found.radius + noiseBand(std::max(bands.search_sigma, bands.scatter)) + EXTRACTION_MARGIN;
}

std::uint64_t BranchSearch::nextFitSeed() {
  return context_.config.seed * FIT_SEED_FACTOR + stream_++;
}

std::uint64_t BranchSearch::nextRefitSeed() {
  return context_.config.seed * FIT_SEED_FACTOR + REFIT_STREAM_START + refit_stream_++;
}
std::uint64_t BranchSearch::nextCutRefitSeed() {
  return context_.config.seed * FIT_SEED_FACTOR + CUT_REFIT_STREAM_START + cut_refit_stream_++;
}

BranchSearch::NearPart BranchSearch::nearPart(const std::vector<int>& cluster, double reach) const {
  NearPart near;
  near.segment = candidates_.where[cluster.front()].segment;
  for (const int k : cluster) {
    const TrunkCoords& c = candidates_.where[k];
    const double gap = c.distance - context_.trunk.cylinders[c.segment].radius;
    if (gap < near.nearest_gap) {
      near.nearest_gap = gap;
      near.segment = c.segment;
    }
    if (gap <= reach) {
      near.pts.push_back(candidates_.pts[k]);
      near.index.push_back(candidates_.index[k]);
    }
  }
  return near;
}

/// The axis the fit starts from: the near part's own direction, pointing away from the trunk.
/// A steep scaffold (central leaders) leaves the trunk more upwards than outwards; its part in
/// the shell is a long, clearly directed cluster, and its own direction is kept up to
/// branches.max_steep_angle_deg from the radial. A short or round cluster's direction says little:
/// the radial replaces it beyond branches.max_radial_angle_deg. None when the near part sits on the
/// trunk axis.
std::optional<BranchSearch::Direction> BranchSearch::direction(const NearPart& near,
                                                               const Cylinder& seg) const {
  const ModelerConfig& config = context_.config;
  Eigen::Vector3d centroid;
  Eigen::Vector3d spread;
  Eigen::Vector3d axis = principalAxis(near.pts, &centroid, &spread);
  Eigen::Vector3d radial =
      (centroid - seg.center) - (centroid - seg.center).dot(seg.axis) * seg.axis;
  if (radial.norm() < 1e-9)
    return std::nullopt;
  radial.normalize();
  if (axis.dot(radial) < 0.0)
    axis = -axis;
  const bool elongated = steep_pass_ || spread(2) > STEEP_ELONGATION * spread(1);
  const double max_angle =
      (elongated ? config.branches.max_steep_angle_deg : config.branches.max_radial_angle_deg) *
      DEG;
  if (config.fit.constrain && angleBetween(axis, radial) > max_angle)
    axis = radial;
  return Direction{radial, axis, max_angle};
}

/// The cylinder of the near part: ours a thin-cylinder fit (its radii through the branch
/// calibration when there is one), the paper's a RANSAC cylinder. Its radius is what its
/// points spread over, shoots and spurs included (the checks and the extraction work with
/// that); *wood_radius is the radius the branch reports.
std::optional<Cylinder> BranchSearch::fit(const NearPart& near, const Cylinder& seg,
                                          const Direction& guess, std::uint64_t seed,
                                          std::vector<int>* inliers, double* wood_radius) {
  const ModelerConfig& config = context_.config;
  const BranchBands& bands = context_.bands;
  CylinderRansacConfig o;
  o.threshold = bands.threshold;
  o.circle_iterations = config.fit.ransac_iterations / 2;
  o.axis_candidates = AXIS_CANDIDATES;
  o.max_axis_deviation = config.fit.constrain ? MAX_AXIS_DEVIATION : PAPER_MAX_AXIS_DEVIATION;
  o.min_radius = MIN_BRANCH_RADIUS_M;
  o.max_radius = config.fit.constrain ? maxBranchRadius(seg) : PAPER_MAX_BRANCH_RADIUS;
  o.seed = seed;
  if (!config.fit.constrain) {
    auto cyl = ransacCylinder(near.pts, guess.axis, o, inliers);
    if (cyl)
      *wood_radius = cyl->radius;
    return cyl;
  }
  // With a branch calibration the fit reports the raw RMS radius and the table maps it.
  const bool calibrated = config.noise.correct_bias && config.branch_calibration.valid();
  const bool raw = calibrated || config.branches.raw_radius;
  double spread = 0.0;
  auto cyl = fitThinCylinder(near.pts, guess.axis, bands.sigma, raw ? 0.0 : bands.scatter,
                             o.max_radius, o.seed, inliers, &spread);
  if (!cyl)
    return cyl;
  *wood_radius = cyl->radius;
  if (config.branchTableCorrects()) {
    const auto& table = config.branch_calibration;
    *wood_radius = table.correct(*wood_radius, bands.table_sigma, MIN_BRANCH_RADIUS_M);
    spread = table.correct(spread, bands.table_sigma, MIN_BRANCH_RADIUS_M);
  }
  cyl->radius = spread;
  return cyl;
}

/// A fit with at least branches.min_points inliers, its axis pointing away from the trunk.
std::optional<Cylinder> BranchSearch::outwardFit(const NearPart& part, const Cylinder& seg,
                                                 const Direction& guess, std::uint64_t seed,
                                                 std::vector<int>* inliers, double* wood_radius) {
  auto cyl = fit(part, seg, guess, seed, inliers, wood_radius);
  if (!cyl || static_cast<int>(inliers->size()) < context_.config.branches.min_points)
    return std::nullopt;
  if (cyl->axis.dot(guess.radial) < 0.0)
    cyl->axis = -cyl->axis;
  return cyl;
}

/// Seen along the trunk a primary points away from it, whatever its elevation; a fit across
/// two branches, or a branch and a shoot, points sideways. Primaries leave the trunk between
/// about 20 deg below and 45 deg above the horizontal, no thicker than the trunk there, and
/// their axis passes the trunk's: a fit that dives, is wider than the trunk or misses it took
/// in something else (a shoot hanging from the branch, a neighbour).
std::optional<BranchSearch::Verdict> BranchSearch::checkDirection(const Candidate& candidate,
                                                                  const Cylinder& fit,
                                                                  const Cylinder& seg,
                                                                  const Direction& guess,
                                                                  double gap) const {
  const ModelerConfig& config = context_.config;
  const auto heading = headingAcrossTheTrunk(fit, seg);
  const bool sideways =
      heading && angleBetween(*heading, guess.radial) > config.branches.max_azimuth_deg * DEG;
  const bool off_ray = candidate.ray && lineAngle(fit.axis, *candidate.ray) > RAY_AGREEMENT;
  if (off_ray)
    return Verdict{BranchRejection::OFF_ITS_RAY, true};
  const double radial_angle = angleBetween(fit.axis, guess.radial);
  const bool judged_before =
      steep_pass_ && radial_angle <= config.branches.max_radial_angle_deg * DEG;
  if (judged_before)
    return Verdict{BranchRejection::NOT_RADIAL, false};
  if (radial_angle > guess.max_angle || sideways)
    return Verdict{BranchRejection::NOT_RADIAL, true};
  if (angleBetween(fit.axis, seg.axis) > (90.0 - config.branches.min_elevation_deg) * DEG)
    return Verdict{BranchRejection::POINTS_DOWN, true};
  if (fit.radius > config.branches.max_diameter_ratio * seg.radius)
    return Verdict{BranchRejection::THICKER_THAN_THE_TRUNK, true};
  if (gap > seg.radius + config.branches.axis_gap_m)
    return Verdict{BranchRejection::MISSES_THE_TRUNK, true};
  return std::nullopt;
}

/// A primary's points lie on its own side of the trunk. A fit with a share of them behind the
/// trunk, past where the candidates start, ran across it through branches on both sides: a
/// crown whose whorls fuse into one cluster at centimetre noise. Kept, it would take both out.
/// A near-vertical fit has no side to be on.
bool BranchSearch::spansTheTrunk(const Cylinder& fit, const Cylinder& seg, const NearPart& near,
                                 const std::vector<int>& inliers) const {
  const auto heading = headingAcrossTheTrunk(fit, seg);
  if (!heading || inliers.empty())
    return false;
  const double behind = seg.radius + context_.bands.inner_gap;
  const auto n = std::count_if(inliers.begin(), inliers.end(), [&](int i) {
    return (near.pts[i] - seg.center).dot(*heading) < -behind;
  });
  return static_cast<double>(n) > MAX_SHARE_BEHIND_THE_TRUNK * static_cast<double>(inliers.size());
}

bool BranchSearch::reachesSurface(const NearPart& near) const {
  return near.nearest_gap <= SURFACE_CONTACT + context_.bands.inner_gap;
}

/// Primaries are at least branches.min_length_m long and start above the ground: a short fragment
/// is a spur, a shoot or what an extraction left of a branch; near the ground it is mixed
/// pixels between the trunk base and the soil. A short fit to a large candidate ran across it
/// (two branches meeting, a branch and its shoot): the halves may each hold a branch.
std::optional<BranchSearch::Verdict> BranchSearch::checkPlace(
    const Candidate& candidate, const Cylinder& fit, const Eigen::Vector3d& attachment) const {
  const ModelerConfig& config = context_.config;
  if (fit.length < config.branches.min_length_m) {
    const bool large =
        static_cast<int>(candidate.members.size()) >= SHORT_SPLIT * config.branches.min_points;
    return Verdict{BranchRejection::TOO_SHORT, large};
  }
  if (attachment.z() - context_.trunk.baseZ() < config.branches.min_height_m)
    return Verdict{BranchRejection::TOO_LOW, false};
  return std::nullopt;
}

void BranchSearch::accept(const Candidate& candidate, const NearPart& near, const Cylinder& fit,
                          double wood_radius, const std::vector<int>& inliers,
                          const Eigen::Vector3d& attachment, bool reaches_surface) {
  const ModelerConfig& config = context_.config;
  const BranchBands& bands = context_.bands;
  Points in;
  BranchFit branch;
  for (const int i : inliers) {
    in.push_back(near.pts[i]);
    branch.inliers.push_back(near.index[i]);
  }
  branch.cylinder = fit;
  branch.cylinder.radius = wood_radius;
  if (config.noise.correct_bias && !config.fit.constrain) {
    branch.cylinder.radius =
        noiseCorrectedRadius(fit, in, bands.sigma, bands.threshold, MIN_BRANCH_RADIUS_M);
  }
  branch.candidates = near.pts.size();
  branch.trunk_segment = near.segment;
  branch.attachment = attachment;
  branch.reaches_surface = reaches_surface;
  if (reaches_surface) {
    branches_.push_back(std::move(branch));
  } else {
    cut_.push_back(
        {std::move(branch), near.nearest_gap,
         rejection(candidates_.pts, candidate.members, BranchRejection::NOT_AT_THE_SURFACE)});
  }
  if (config.fit.constrain)
    searchRest(candidate.members, fit);
}

/// A candidate that fits no branch may be several branches fused into one cluster (close
/// neighbours, a shoot bridging two): parted along its strongest ray, or split in two by
/// position, while the budget lasts. Else it is turned down, and said so.
void BranchSearch::reject(const Candidate& candidate, int segment, Verdict verdict) {
  const ModelerConfig& config = context_.config;
  const bool could_split =
      verdict.splittable && config.fit.constrain &&
      static_cast<int>(candidate.members.size()) >= SPLIT_MIN_SIZE * config.branches.min_points;
  if (could_split && budgetLeft()) {
    Points cluster_pts;
    for (const int k : candidate.members)
      cluster_pts.push_back(candidates_.pts[k]);
    if (splitAlongRay(candidate, cluster_pts, segment) || splitInHalves(candidate, cluster_pts))
      return;
  }
  if (!steep_pass_) {
    turned_down_.push_back(
        {candidate.members, rejection(candidates_.pts, candidate.members, verdict.reason,
                                      could_split && !budgetLeft())});
  }
}

/// Branches leave the trunk as rays: the points along the strongest ray through the candidate
/// are one candidate, the rest others. Once parted, a candidate is halved by position instead.
bool BranchSearch::splitAlongRay(const Candidate& candidate, const Points& cluster_pts,
                                 int segment) {
  const ModelerConfig& config = context_.config;
  const double sigma = context_.bands.search_sigma;
  if (!config.branches.ray_split || sigma < config.branches.ray_split_min_noise_m || candidate.ray)
    return false;
  const auto ray =
      strongestRay(cluster_pts, context_.trunk.cylinders[segment],
                   config.branches.min_elevation_deg, config.branches.max_steep_angle_deg);
  if (!ray)
    return false;
  const double tube = std::max(noiseBand(sigma), RAY_MIN_BAND) + RAY_TUBE_RADIUS;
  std::vector<int> on, rest;
  for (const int k : candidate.members)
    (rayDistance(*ray, candidates_.pts[k]) < tube ? on : rest).push_back(k);
  if (static_cast<int>(on.size()) < config.branches.min_points || rest.empty())
    return false;
  work_.push_back({std::move(on), ray->direction});
  ++extractions_;
  pushParts(rest);
  return true;
}

bool BranchSearch::splitInHalves(const Candidate& candidate, const Points& cluster_pts) {
  const auto labels = kMeans(cluster_pts, 2, HALVES_ITERATIONS,
                             context_.config.seed * HALVES_SEED_FACTOR + stream_++);
  std::vector<int> halves[2];
  for (std::size_t k = 0; k < candidate.members.size(); ++k)
    halves[labels[k]].push_back(candidate.members[k]);
  if (halves[0].empty() || halves[1].empty())
    return false;
  work_.push_back({std::move(halves[0]), std::nullopt});
  work_.push_back({std::move(halves[1]), std::nullopt});
  extractions_ += 2;
  return true;
}

/// Takes a found line's points (a branch, a wire) out of a cluster and looks again at what
/// remains of it. Returns the points taken out.
std::vector<int> BranchSearch::searchRest(const std::vector<int>& cluster, const Cylinder& found) {
  const double reach = extractionReach(found);
  std::vector<int> taken, rest;
  for (const int k : cluster)
    (axisDistance(found, candidates_.pts[k]) > reach ? rest : taken).push_back(k);
  if (static_cast<int>(rest.size()) >= REMAINDER_MIN_SIZE * context_.config.branches.min_points) {
    if (budgetLeft()) {
      pushParts(rest);
    } else if (rejected_) {
      // Said, not silently dropped: what may hold another branch was not looked at.
      rejected_->push_back(
          rejection(candidates_.pts, rest, BranchRejection::REMAINDER_NOT_SEARCHED, true));
    }
  }
  return taken;
}

/// Parts of a cluster are clustered again: a part may have fallen apart.
void BranchSearch::pushParts(const std::vector<int>& rest) {
  for (auto& part : clustersOf(rest)) {
    work_.push_back({std::move(part), std::nullopt});
    ++extractions_;
  }
}

std::vector<std::vector<int>> BranchSearch::clustersOf(const std::vector<int>& members) const {
  Points pts;
  for (const int k : members)
    pts.push_back(candidates_.pts[k]);
  const BranchConfig& b = context_.config.branches;
  auto clusters = euclideanClusters(pts, b.cluster_tolerance_m, b.min_points);
  for (auto& cluster : clusters) {
    for (int& k : cluster)
      k = members[k];
  }
  return clusters;
}

}  // namespace detail
}  // namespace modeling
}  // namespace dormant_tree_modeling
