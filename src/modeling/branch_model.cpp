#include "dormant_tree_modeling/modeling/branch_model.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <optional>
#include <utility>

#include "dormant_tree_modeling/common/parallel.h"
#include "dormant_tree_modeling/common/statistics.h"
#include "dormant_tree_modeling/modeling/branch_rays.h"
#include "dormant_tree_modeling/modeling/noise_band.h"
#include "dormant_tree_modeling/modeling/point_index.h"

namespace dormant_tree_modeling {
namespace modeling {

namespace {

constexpr double DEG = M_PI / 180.0;
constexpr double MIN_BRANCH_RADIUS = 0.002;
constexpr double SURFACE_CONTACT = 0.05;
// A fit cut off from the trunk surface (branch_keep_cut_off): its way back to the trunk is
// walked in steps, each holding a share of the returns around the fit's centre, and part of it
// must lie off every accepted fit.
constexpr double CUT_WALK_STEP = 0.01;    // m
constexpr double CUT_WALK_REACH = 1.0;    // m, beyond any fit's way back
constexpr double CUT_FILL_SHARE = 0.2;    // of the returns around the fit's centre, per step
constexpr int CUT_FILL_MIN_POINTS = 3;    // per step, however sparse the fit
constexpr double CUT_MIN_OWN_WAY = 0.03;  // m of the way off accepted fits
// A candidate of this many times branch_min_points whose fit is too short is split and retried.
constexpr int SHORT_SPLIT = 12;
constexpr double STEEP_ELONGATION = 16.0;  // variance ratio (4:1 in length) of a directed cluster
// A candidate parted along a ray is a branch along it: its fit stays within this of the ray.
constexpr double RAY_AGREEMENT = 20.0 * DEG;
// Its points: within the noise band (2.5 sigma, at least RAY_MIN_BAND) plus RAY_TUBE_RADIUS (a
// thin branch's radius with a margin) of the ray.
constexpr double RAY_MIN_BAND = 0.01;     // m
constexpr double RAY_TUBE_RADIUS = 0.01;  // m
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

/// Where a point sits relative to the trunk model.
struct TrunkCoords {
  int segment = -1;
  double s = 0.0;
  double distance = 0.0;  // to the segment cylinder's axis
};

TrunkCoords locate(const TrunkModel& trunk, const Eigen::Vector3d& p) {
  TrunkCoords c;
  c.s = trunk.centerline.project(p);
  c.segment = trunk.cylinderAt(c.s);
  if (c.segment >= 0)
    c.distance = axisDistance(trunk.cylinders[c.segment], p);
  return c;
}

/// A turned-down candidate: the centroid and count of its members (indices into pts).
RejectedBranch rejection(const Points& pts, const std::vector<int>& members, std::string reason) {
  RejectedBranch r;
  for (const int k : members)
    r.centroid += pts[k];
  r.centroid /= static_cast<double>(members.size());
  r.points = static_cast<int>(members.size());
  r.reason = std::move(reason);
  return r;
}

/// Closest points between two lines p + t u and q + s v: returns the point on the first line
/// and the distance between the lines.
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

/// A thin horizontal line that continues straight through the trunk and out of its other
/// side is a trellis wire (a branch ends at the trunk); preprocessing misses wires that run
/// shorter than wire_min_length inside a tight crop. The wires of a row are parallel: when
/// preprocessing found some, a piece crossing them is no wire (a branch and the one opposite
/// it continue each other's line as well).
bool looksLikeWire(const Cylinder& c, const Cylinder& trunk_segment, const PointIndex& index,
                   double sigma, const std::vector<Eigen::Vector3d>& wire_directions) {
  constexpr double MAX_WIRE_RADIUS = 0.004;
  constexpr double MAX_WIRE_TILT = 15.0 * DEG;
  constexpr double MAX_WIRE_CROSSING = 15.0 * DEG;
  constexpr double STEP = 0.02;
  if (c.radius > MAX_WIRE_RADIUS || std::abs(c.axis.z()) > std::sin(MAX_WIRE_TILT))
    return false;
  if (!wire_directions.empty()) {
    const Eigen::Vector2d level = c.axis.head<2>().normalized();
    bool parallel = false;
    for (const auto& w : wire_directions) {
      parallel =
          parallel || std::abs(level.dot(w.head<2>().normalized())) >= std::cos(MAX_WIRE_CROSSING);
    }
    if (!parallel)
      return false;
  }
  // Walk the axis backwards through the trunk: sample the far side from 5 to 40 cm past the
  // trunk surface.
  Eigen::Vector3d through;
  lineGap(c.center, c.axis, trunk_segment.center, trunk_segment.axis, &through);
  const double t_trunk = (through - c.center).dot(c.axis);
  const double tolerance = 0.008 + sigma;
  int samples = 0, occupied = 0;
  for (double d = trunk_segment.radius + 0.05; d <= trunk_segment.radius + 0.4; d += STEP) {
    const Eigen::Vector3d q = c.center + (t_trunk - d) * c.axis;
    ++samples;
    occupied += index.countWithin(q, tolerance, 1) > 0;
  }
  return samples > 0 && occupied >= 0.8 * samples;
}

/// Keeps the fits not marked in drop; the others are reported as turned down for reason.
void removeMarked(std::vector<BranchFit>& branches, const std::vector<char>& drop,
                  const char* reason, std::vector<RejectedBranch>* rejected) {
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

}  // namespace

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

/// Walks a fit's axis from its centre towards the trunk (against the axis, which points away)
/// and calls visit(q) for each step at most `gap` off the trunk surface until `inner_gap` or
/// the axis' closest approach to the trunk; stops early, returning false, when visit does.
template <typename Visit>
bool walkToSurface(const Cylinder& fit, const Cylinder& seg, double inner_gap, double gap,
                   Visit visit) {
  double last = 1e300;
  for (double t = 0.0; t < CUT_WALK_REACH; t += CUT_WALK_STEP) {
    const Eigen::Vector3d q = fit.center - t * fit.axis;
    const double d = axisDistance(seg, q) - seg.radius;
    if (d < inner_gap || d > last)
      return true;
    last = d;
    if (d <= gap && !visit(q))
      return false;
  }
  return false;
}

/// Whether returns fill a fit's axis from inner_gap off the trunk surface out to the fit's
/// nearest point (gap), at CUT_FILL_SHARE of the density around the fit's centre: a branch
/// crossing another near the trunk is cut in two by the other's extraction, and its outer
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

/// How much of the way from a fit to the trunk lies off every accepted fit (m): there the
/// returns are the fit's own near part, cut off by a crossing branch's extraction. A shoot's
/// way back runs inside its parent, and a piece of an accepted branch inside that branch.
double ownWayToSurface(const Cylinder& fit, const Cylinder& seg,
                       const std::vector<BranchFit>& accepted, double inner_gap, double gap,
                       double tube) {
  double own = 0.0;
  walkToSurface(fit, seg, inner_gap, gap, [&](const Eigen::Vector3d& q) {
    for (const auto& b : accepted) {
      const Cylinder& c = b.cylinder;
      if (axisDistance(c, q) < c.radius + tube &&
          std::abs((q - c.center).dot(c.axis)) < 0.5 * c.length)
        return true;
    }
    own += CUT_WALK_STEP;
    return true;
  });
  return own;
}

std::vector<BranchFit> modelBranches(const Points& pts, const PointIndex& index,
                                     const TrunkModel& trunk, const std::vector<int>& region,
                                     const ModelerConfig& config,
                                     std::vector<RejectedBranch>* rejected,
                                     const std::vector<Eigen::Vector3d>& wire_directions) {
  std::vector<BranchFit> branches;
  if (trunk.cylinders.empty())
    return branches;
  // Bands follow the range noise; radii lose the noise and the beam's lateral scatter.
  const double sigma = trunk.noise_sigma;
  const double scatter = config.ours_correct_noise_bias ? trunk.scatter : 0.0;
  double threshold = config.cylinder_threshold;
  if (config.ours_derive_parameters)
    threshold = std::max(threshold, noiseBand(sigma));
  const double base_z = trunk.baseZ();
  const double s_lo = trunk.cylinder_ranges.front().first - 0.05;
  const double s_hi = trunk.cylinder_ranges.back().second + 0.05;

  // Candidate points and where they sit.
  std::vector<int> candidates;
  std::vector<TrunkCoords> where;
  // Where every point sits, on all cores; then the candidates in index order.
  const int n_points = static_cast<int>(config.ours_branch_shell ? pts.size() : region.size());
  std::vector<TrunkCoords> located(n_points);
  parallelFor(n_points, [&](int k) {
    located[k] = locate(trunk, pts[config.ours_branch_shell ? k : region[k]]);
  });
  auto consider = [&](int i, const TrunkCoords& c) {
    if (c.segment < 0 || c.s < s_lo || c.s > s_hi)
      return;
    const double r = trunk.cylinders[c.segment].radius;
    if (c.distance <= r + threshold)
      return;  // on the trunk surface
    // The shell starts away from the trunk: near its surface the noise of the trunk links
    // every branch to every other.
    if (config.ours_branch_shell && (c.distance < r + config.branch_inner_gap ||
                                     c.distance > r + config.branch_fit_length + 0.05)) {
      return;
    }
    candidates.push_back(i);
    where.push_back(c);
  };
  for (int k = 0; k < n_points; ++k)
    consider(config.ours_branch_shell ? k : region[k], located[k]);
  Points cand_pts;
  for (const int i : candidates)
    cand_pts.push_back(pts[i]);
  const auto clusters =
      euclideanClusters(cand_pts, config.branch_cluster_tolerance, config.branch_min_points);

  std::uint64_t stream = 0;
  // Work list: clusters, and what is left of a cluster after a branch was taken out of it (two
  // branches, or a branch and a shoot, close enough to form one cluster).
  struct Candidate {
    std::vector<int> members;  // indices into cand_pts
    // Set when parted from a fused candidate along its strongest ray: that ray's direction.
    std::optional<Eigen::Vector3d> ray;
  };
  std::vector<Candidate> work;
  // Fits whose points start away from the trunk surface with returns filling the way there.
  struct CutFit {
    BranchFit fit;
    double gap;  // of its nearest point from the trunk surface
    RejectedBranch as_rejected;
  };
  std::vector<CutFit> cut;
  // How far off the trunk surface candidates start: a branch's points begin there or closer.
  const double inner_gap = config.ours_branch_shell ? config.branch_inner_gap : threshold;
  for (auto it = clusters.rbegin(); it != clusters.rend(); ++it)
    work.push_back({*it, std::nullopt});
  int extractions = 0;
  // Parts of a cluster are clustered again: a part may have fallen apart.
  auto pushParts = [&](const std::vector<int>& rest) {
    Points rest_pts;
    for (const int k : rest)
      rest_pts.push_back(cand_pts[k]);
    for (const auto& part :
         euclideanClusters(rest_pts, config.branch_cluster_tolerance, config.branch_min_points)) {
      std::vector<int> mapped;
      for (const int k : part)
        mapped.push_back(rest[k]);
      work.push_back({std::move(mapped), std::nullopt});
      ++extractions;
    }
  };
  while (!work.empty()) {
    const std::vector<int> cluster = std::move(work.back().members);
    const std::optional<Eigen::Vector3d> along_ray = work.back().ray;
    work.pop_back();
    // The part of the branch near the trunk: where diameters are measured and pruning cuts.
    Points sub;
    std::vector<int> sub_index;
    double nearest_gap = 1e300;
    int segment = where[cluster.front()].segment;
    double min_d = 1e300;
    for (const int k : cluster) {
      const double r = trunk.cylinders[where[k].segment].radius;
      const double gap = where[k].distance - r;
      nearest_gap = std::min(nearest_gap, gap);
      if (gap < min_d) {
        min_d = gap;
        segment = where[k].segment;
      }
      if (gap <= config.branch_fit_length) {
        sub.push_back(cand_pts[k]);
        sub_index.push_back(candidates[k]);
      }
    }
    // A candidate that fits no branch may be several branches fused into one cluster (close
    // neighbours, a shoot bridging two): split in two by position and look at each half.
    auto reject = [&](const char* reason, bool splittable) {
      const bool could_split = splittable && config.ours_constrain_ransac &&
                               static_cast<int>(cluster.size()) >= 4 * config.branch_min_points;
      const bool budget_spent = extractions >= config.branch_search_budget;
      if (could_split && !budget_spent) {
        Points cluster_pts;
        for (const int k : cluster)
          cluster_pts.push_back(cand_pts[k]);
        // Branches leave the trunk as rays: the points along the strongest ray through the
        // candidate are one candidate, the rest others. Once parted, halves by position.
        if (config.branch_ray_split && sigma >= config.branch_ray_split_min_noise && !along_ray) {
          const auto ray = strongestRay(cluster_pts, trunk.cylinders[segment],
                                        config.branch_min_elevation, config.branch_max_steep_angle);
          if (ray) {
            const double tube = std::max(noiseBand(sigma), RAY_MIN_BAND) + RAY_TUBE_RADIUS;
            std::vector<int> on, rest;
            for (const int k : cluster)
              (rayDistance(*ray, cand_pts[k]) < tube ? on : rest).push_back(k);
            if (static_cast<int>(on.size()) >= config.branch_min_points && !rest.empty()) {
              work.push_back({std::move(on), ray->direction});
              ++extractions;
              pushParts(rest);
              return;
            }
          }
        }
        const auto labels = kMeans(cluster_pts, 2, 20, config.seed * 7757ULL + stream++);
        std::vector<int> halves[2];
        for (std::size_t k = 0; k < cluster.size(); ++k)
          halves[labels[k]].push_back(cluster[k]);
        if (!halves[0].empty() && !halves[1].empty()) {
          work.push_back({std::move(halves[0]), std::nullopt});
          work.push_back({std::move(halves[1]), std::nullopt});
          extractions += 2;
          return;
        }
      }
      if (rejected) {
        rejected->push_back(rejection(cand_pts, cluster,
                                      could_split && budget_spent
                                          ? std::string(reason) + " (search budget spent)"
                                          : std::string(reason)));
      }
    };
    // Take a found line's points (a branch, a wire) out and look again at what remains of the
    // cluster. Returns the points taken out.
    auto searchRest = [&](const Cylinder& found) {
      std::vector<int> taken;
      const double reach = found.radius + noiseBand(std::max(sigma, scatter)) + 0.005;
      std::vector<int> rest;
      for (const int k : cluster) {
        if (axisDistance(found, cand_pts[k]) > reach) {
          rest.push_back(k);
        } else {
          taken.push_back(k);
        }
      }
      if (static_cast<int>(rest.size()) >= 2 * config.branch_min_points) {
        if (extractions < config.branch_search_budget) {
          pushParts(rest);
        } else if (rejected) {
          // Said, not silently dropped: what may hold another branch was not looked at.
          rejected->push_back(
              rejection(cand_pts, rest, "remainder not searched (search budget spent)"));
        }
      }
      return taken;
    };
    if (static_cast<int>(sub.size()) < config.branch_min_points) {
      reject("too few points", false);
      continue;
    }
    const Cylinder& seg = trunk.cylinders[segment];
    Eigen::Vector3d centroid;
    Eigen::Vector3d spread;
    Eigen::Vector3d axis = principalAxis(sub, &centroid, &spread);
    Eigen::Vector3d radial =
        (centroid - seg.center) - (centroid - seg.center).dot(seg.axis) * seg.axis;
    if (radial.norm() < 1e-9) {
      reject("no fit", true);
      continue;
    }
    radial.normalize();
    if (axis.dot(radial) < 0.0)
      axis = -axis;
    // A steep scaffold (central leaders) leaves the trunk more upwards than outwards; its part
    // in the shell is a long, clearly directed cluster, and its own direction is kept up to
    // branch_max_steep_angle from the radial. A short or round cluster's direction says
    // little: the radial replaces it beyond branch_max_radial_angle.
    const bool elongated = spread(2) > STEEP_ELONGATION * spread(1);
    const double max_angle =
        (elongated ? config.branch_max_steep_angle : config.branch_max_radial_angle) * DEG;
    if (config.ours_constrain_ransac &&
        std::acos(std::clamp(axis.dot(radial), -1.0, 1.0)) > max_angle)
      axis = radial;
    CylinderRansacOptions o;
    o.threshold = threshold;
    o.circle_iterations = config.ransac_iterations / 2;
    o.axis_candidates = 8;
    o.max_axis_deviation = config.ours_constrain_ransac ? 30.0 * DEG : 35.0 * DEG;
    o.min_radius = MIN_BRANCH_RADIUS;
    o.max_radius = config.ours_constrain_ransac ? std::max(MIN_BRANCH_RADIUS * 2, seg.radius) : 0.3;
    o.seed = config.seed * 15485863ULL + stream++;
    std::vector<int> inliers;
    // With a branch calibration the fit reports the raw RMS radius and the table maps it.
    const bool calibrated = config.ours_correct_noise_bias && config.branch_calibration.valid();
    const bool raw = calibrated || config.branch_raw_radius;
    auto cyl = config.ours_constrain_ransac ? fitThinCylinder(sub, axis, sigma, raw ? 0.0 : scatter,
                                                              o.max_radius, o.seed, &inliers)
                                            : ransacCylinder(sub, axis, o, &inliers);
    if (cyl && calibrated && !config.branch_raw_radius && config.ours_constrain_ransac)
      cyl->radius = config.branch_calibration.correct(cyl->radius, sigma, MIN_BRANCH_RADIUS);
    if (!cyl || static_cast<int>(inliers.size()) < config.branch_min_points) {
      reject("no fit", true);
      continue;
    }
    if (cyl->axis.dot(radial) < 0.0)
      cyl->axis = -cyl->axis;
    bool reaches_surface = true;
    Eigen::Vector3d attachment;
    const double gap = lineGap(cyl->center, cyl->axis, seg.center, seg.axis, &attachment);
    if (config.ours_constrain_ransac) {
      // Seen along the trunk a primary points away from it, whatever its elevation; a fit
      // across two branches, or a branch and a shoot, points sideways.
      const Eigen::Vector3d across = cyl->axis - cyl->axis.dot(seg.axis) * seg.axis;
      const bool sideways =
          across.norm() > 0.3 && std::acos(std::clamp(across.normalized().dot(radial), -1.0, 1.0)) >
                                     config.branch_max_azimuth * DEG;
      const bool off_ray = along_ray && std::acos(std::clamp(std::abs(cyl->axis.dot(*along_ray)),
                                                             -1.0, 1.0)) > RAY_AGREEMENT;
      if (off_ray) {
        reject("off its ray", true);
        continue;
      }
      if (std::acos(std::clamp(cyl->axis.dot(radial), -1.0, 1.0)) > max_angle || sideways) {
        reject("not radial", true);
        continue;
      }
      // Primaries leave the trunk between about 20 deg below and 45 deg above the horizontal,
      // and no thicker than the trunk there: a fit that dives or is wider than the trunk took
      // in something else (a shoot hanging from the branch, a neighbour).
      if (std::acos(std::clamp(cyl->axis.dot(seg.axis), -1.0, 1.0)) >
          (90.0 - config.branch_min_elevation) * DEG) {
        reject("points down", true);
        continue;
      }
      if (cyl->radius > config.branch_max_diameter_ratio * seg.radius) {
        reject("thicker than the trunk", true);
        continue;
      }
      if (gap > seg.radius + config.branch_axis_gap) {
        reject("misses the trunk", true);
        continue;
      }
      reaches_surface = nearest_gap <= SURFACE_CONTACT + inner_gap;
      // A branch crossing this one near the trunk may have taken its near part out with it.
      if (!reaches_surface &&
          !(config.branch_keep_cut_off &&
            filledToSurface(*cyl, seg, index, inner_gap, nearest_gap, cyl->radius + threshold))) {
        reject("not at the surface", true);
        continue;
      }
    }
    if (config.ours_constrain_ransac) {
      // Primaries are at least 0.2 m long and start above the ground: a short fragment is a
      // spur, a shoot or what an extraction left of a branch; near the ground it is mixed
      // pixels between the trunk base and the soil.
      if (cyl->length < config.branch_min_length) {
        // A short fit to a large candidate ran across it (two branches meeting, a branch and
        // its shoot): the halves may each hold a branch.
        reject("too short",
               static_cast<int>(cluster.size()) >= SHORT_SPLIT * config.branch_min_points);
        continue;
      }
      if (attachment.z() - base_z < config.branch_min_height) {
        reject("too low", false);
        continue;
      }
    }
    if (config.ours_remove_clutter && looksLikeWire(*cyl, seg, index, sigma, wire_directions)) {
      // A wire passing close to a branch joins its cluster: the wire's points go, the rest is
      // looked at again.
      const std::vector<int> wire = searchRest(*cyl);
      if (rejected && !wire.empty())
        rejected->push_back(rejection(cand_pts, wire, "a wire"));
      continue;
    }
    Points in;
    BranchFit fit;
    for (const int i : inliers) {
      in.push_back(sub[i]);
      fit.inliers.push_back(sub_index[i]);
    }
    if (config.ours_correct_noise_bias && !config.ours_constrain_ransac) {
      cyl->radius = noiseCorrectedRadius(*cyl, in, sigma, threshold, MIN_BRANCH_RADIUS);
    }
    fit.cylinder = *cyl;
    fit.candidates = sub.size();
    fit.trunk_segment = segment;
    fit.attachment = attachment;
    fit.reaches_surface = reaches_surface;
    if (reaches_surface) {
      branches.push_back(std::move(fit));
    } else {
      cut.push_back(
          {std::move(fit), nearest_gap, rejection(cand_pts, cluster, "not at the surface")});
    }
    if (config.ours_constrain_ransac)
      searchRest(*cyl);
  }
  // A fit cut off from the trunk is judged once every branch reaching the trunk is known: its
  // way back must not lie all inside them.
  for (auto& c : cut) {
    const Cylinder& seg = trunk.cylinders[c.fit.trunk_segment];
    const double own = ownWayToSurface(c.fit.cylinder, seg, branches, inner_gap, c.gap,
                                       c.fit.cylinder.radius + threshold);
    if (own < CUT_MIN_OWN_WAY) {
      if (rejected)
        rejected->push_back(c.as_rejected);
      continue;
    }
    branches.push_back(std::move(c.fit));
  }
  if (config.ours_constrain_ransac) {
    // One branch split into two clusters (a gap in its returns) appears twice: keep the one
    // that reaches the trunk surface, else the larger.
    std::vector<char> drop(branches.size(), 0);
    for (std::size_t i = 0; i < branches.size(); ++i) {
      for (std::size_t k = i + 1; k < branches.size(); ++k) {
        if (drop[i] || drop[k])
          continue;
        const auto& a = branches[i];
        const auto& b = branches[k];
        // Two pieces of a curved branch: the longer one's axis is the better determined (the
        // other piece, whichever reaches the trunk, is short and bent away from the branch).
        const bool curved = config.branch_merge_curved && curvedPieces(a, b);
        if (!curved && !sameBranch(a, b))
          continue;
        const bool keep_a = curved ? a.cylinder.length >= b.cylinder.length
                            : a.reaches_surface != b.reaches_surface
                                ? a.reaches_surface
                                : a.inliers.size() >= b.inliers.size();
        drop[keep_a ? k : i] = 1;
      }
    }
    removeMarked(branches, drop, "duplicate", rejected);
  }
  if (config.branch_min_relative_points > 0.0 && branches.size() >= MIN_BRANCHES_FOR_MEDIAN) {
    // The primaries of one tree near its trunk return comparable numbers of points; a detection
    // with a small fraction of the usual is a shoot on a primary, the tip of a neighbour's
    // branch reaching in or a streak of mixed pixels.
    std::vector<double> counts;
    for (const auto& b : branches)
      counts.push_back(static_cast<double>(b.inliers.size()));
    const double floor = config.branch_min_relative_points * median(std::move(counts));
    std::vector<char> drop(branches.size(), 0);
    for (std::size_t i = 0; i < branches.size(); ++i)
      drop[i] = static_cast<double>(branches[i].inliers.size()) < floor;
    removeMarked(branches, drop, "few points for this tree", rejected);
  }
  return branches;
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
