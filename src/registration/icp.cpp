#include "dormant_tree_modeling/registration/icp.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>
#include <optional>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/parallel.h"
#include "dormant_tree_modeling/modeling/point_index.h"

namespace dormant_tree_modeling {
namespace registration {

namespace {

constexpr double DEG = M_PI / 180.0;

struct Match {
  int source, target;
  double residual;  // signed point-to-plane distance, or the point-to-ray distance
  double gap;       // how far apart the two are: 3-D, or across the ray for `across` pairs
  bool across;      // seen from opposite sides: point-to-ray
};

// A source axis sample paired with the other side's axis sample nearest to it.
struct AxisMatch {
  int source, target;
  double gap;  // offset across the target axis
};

// Pairs of branch-axis samples seen from opposite sides: a station's estimate of a branch axis
// from its half, against the other side's estimate from the other half.
std::vector<AxisMatch> matchAxes(const AxisSamples& source, const AxisSamples& target,
                                 const modeling::PointIndex& index, const Eigen::Isometry3d& t,
                                 double limit, const IcpConfig& c) {
  const double min_parallel = std::cos(c.axis_max_angle_deg * DEG);
  std::vector<AxisMatch> found(source.size());
  std::vector<char> valid(source.size(), 0);
  parallelFor(static_cast<int>(source.size()), [&](int i) {
    const Eigen::Vector3d p = t * source.points[i];
    const int j = index.nearestOne(p);
    if (j < 0 || (t.linear() * source.view_dirs[i]).dot(target.view_dirs[j]) >= c.across_cos)
      return;
    const Eigen::Vector3d& a = target.directions[j];
    if (std::abs((t.linear() * source.directions[i]).dot(a)) < min_parallel)
      return;
    const Eigen::Vector3d d = p - target.points[j];
    const double gap = (d - d.dot(a) * a).norm();
    if (gap > limit)
      return;
    found[i] = {i, j, gap};
    valid[i] = 1;
  });
  std::vector<AxisMatch> out;
  for (std::size_t i = 0; i < found.size(); ++i) {
    if (valid[i])
      out.push_back(found[i]);
  }
  return out;
}

// Two unit vectors spanning the plane normal to d.
void planeBasis(const Eigen::Vector3d& d, Eigen::Vector3d& u, Eigen::Vector3d& v) {
  const Eigen::Vector3d a =
      std::abs(d.x()) < 0.9 ? Eigen::Vector3d::UnitX() : Eigen::Vector3d::UnitY();
  u = d.cross(a).normalized();
  v = d.cross(u);
}

// ICP needs this many points in each cloud, and this many pairs in each iteration.
constexpr std::size_t MIN_POINTS = 10;
constexpr std::size_t MIN_PAIRS = 10;
// Steps within this many times the convergence limits, this many in a row, are a cycle
// between two near-equal poses: as converged as hard nearest-neighbour pairs get.
constexpr double CYCLE_STEP_FACTOR = 10.0;
constexpr int CYCLE_STEPS = 4;

// One pyramid level's clouds and what pairs them.
struct LevelPair {
  const Surface& source;
  const Surface& target;
  const modeling::PointIndex& index;  // of the target
  const AxisSamples& source_axes;
  const AxisSamples& target_axes;
  const modeling::PointIndex* axis_index;  // of the target's axes; null: no axis pairs
  double limit;                            // m: farther pairs are no pairs
};

// The pairs of one iteration, trimmed, and the share of source points close to the target.
struct Pairs {
  std::vector<Match> used;
  std::vector<AxisMatch> axes;
  double overlap = 0;
};

// Each source point with its nearest target point: point-to-plane, or point-to-ray when the
// two were seen from opposite sides.
void matchPoints(const LevelPair& clouds, const Eigen::Isometry3d& t, const IcpConfig& c,
                 std::vector<Match>& matches, std::vector<char>& valid) {
  const Eigen::Matrix3d rot = t.linear();
  parallelFor(static_cast<int>(clouds.source.size()), [&](int i) {
    valid[i] = 0;
    const Eigen::Vector3d p = t * clouds.source.points[i];
    const int j = clouds.index.nearestOne(p);
    if (j < 0)
      return;
    const Eigen::Vector3d& n = clouds.target.normals[j];
    if (n.isZero())
      return;
    const Eigen::Vector3d d = p - clouds.target.points[j];
    if (d.squaredNorm() > clouds.limit * clouds.limit)
      return;
    const Eigen::Vector3d& vt = clouds.target.view_dirs[j];
    const bool across = !vt.isZero() && !clouds.source.view_dirs[i].isZero() &&
                        (rot * clouds.source.view_dirs[i]).dot(vt) < c.across_cos;
    const double ray_gap = across ? (d - d.dot(vt) * vt).norm() : 0.0;
    matches[i] = {i, j, across ? ray_gap : d.dot(n), across ? ray_gap : d.norm(), across};
    valid[i] = 1;
  });
}

// The pairs an iteration uses: the point pairs (without the opposite-side ones when axis pairs
// say where the branches are) and the axis pairs, each kept to its `trim` share of the closest.
Pairs pairUp(const LevelPair& clouds, const Eigen::Isometry3d& t, const IcpConfig& c,
             std::vector<Match>& matches, std::vector<char>& valid) {
  matchPoints(clouds, t, c, matches, valid);
  Pairs pairs;
  std::size_t close = 0;
  for (std::size_t i = 0; i < clouds.source.size(); ++i) {
    if (!valid[i])
      continue;
    close += matches[i].gap <= c.overlap_distance_m;
    if (!(clouds.axis_index && matches[i].across))
      pairs.used.push_back(matches[i]);
  }
  pairs.overlap = static_cast<double>(close) / clouds.source.size();
  if (clouds.axis_index) {
    pairs.axes =
        matchAxes(clouds.source_axes, clouds.target_axes, *clouds.axis_index, t, clouds.limit, c);
    const std::size_t axis_keep = static_cast<std::size_t>(c.trim * pairs.axes.size());
    if (axis_keep < pairs.axes.size()) {
      std::nth_element(pairs.axes.begin(), pairs.axes.begin() + axis_keep, pairs.axes.end(),
                       [](const AxisMatch& a, const AxisMatch& b) { return a.gap < b.gap; });
      pairs.axes.resize(axis_keep);
    }
  }
  return pairs;
}

// Keeps the `trim` share (at least MIN_PAIRS) of the point pairs with the smallest residuals.
void trimPairs(std::vector<Match>& used, double trim) {
  const std::size_t keep =
      std::min(used.size(), std::max(MIN_PAIRS, static_cast<std::size_t>(trim * used.size())));
  if (keep > 0) {
    std::nth_element(
        used.begin(), used.begin() + (keep - 1), used.end(),
        [](const Match& a, const Match& b) { return std::abs(a.residual) < std::abs(b.residual); });
  }
  used.resize(keep);
}

// The linearised point-to-plane system in a small rotation w and translation t, Huber-weighted.
struct NormalEquations {
  Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
  Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();

  // One row: residual e along unit n at the centred point p, weight w.
  void addRow(const Eigen::Vector3d& p, const Eigen::Vector3d& n, double e, double w) {
    Eigen::Matrix<double, 6, 1> J;
    J << p.cross(n), n;
    A += w * J * J.transpose();
    b -= w * J * e;
  }
  // The offset d counted only across a line of direction dir (a ray, a branch axis).
  void addAcross(const Eigen::Vector3d& p, const Eigen::Vector3d& dir, const Eigen::Vector3d& d,
                 double w) {
    Eigen::Vector3d u, v;
    planeBasis(dir, u, v);
    addRow(p, u, d.dot(u), w);
    addRow(p, v, d.dot(v), w);
  }
};

// One Gauss-Newton step of a level: the system about the pairs' centroid (so rotation and
// translation stay on one scale), its rmse and conditioning, and the step it solves to.
struct Step {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();
  Eigen::Matrix<double, 6, 1> x;
  double rmse = 0, conditioning = 0;
};

Eigen::Vector3d pairCentroid(const LevelPair& clouds, const Pairs& pairs,
                             const Eigen::Isometry3d& t) {
  Eigen::Vector3d centre = Eigen::Vector3d::Zero();
  for (const auto& m : pairs.used)
    centre += t * clouds.source.points[m.source];
  for (const auto& m : pairs.axes)
    centre += t * clouds.source_axes.points[m.source];
  return centre / static_cast<double>(pairs.used.size() + pairs.axes.size());
}

Step solveStep(const LevelPair& clouds, const Pairs& pairs, const Eigen::Isometry3d& t,
               const IcpConfig& c) {
  const double n_pairs = static_cast<double>(pairs.used.size() + pairs.axes.size());
  const Eigen::Vector3d centre = pairCentroid(clouds, pairs, t);
  const auto huberWeight = [&](double e) {
    return std::abs(e) <= c.huber_m ? 1.0 : c.huber_m / std::abs(e);
  };
  NormalEquations eq;
  double sq = 0, radius_sq = 0;
  for (const auto& m : pairs.used) {
    const Eigen::Vector3d q = t * clouds.source.points[m.source];
    const Eigen::Vector3d p = q - centre;
    radius_sq += p.squaredNorm();
    const double w = huberWeight(m.residual);
    sq += m.residual * m.residual;
    if (!m.across) {
      eq.addRow(p, clouds.target.normals[m.target], m.residual, w);
      continue;
    }
    // Seen from opposite sides, the two points lie on opposite halves of a branch: only the
    // offset across the target's ray says how far apart the branch axes are.
    eq.addAcross(p, clouds.target.view_dirs[m.target], q - clouds.target.points[m.target], w);
  }
  for (const auto& m : pairs.axes) {
    const Eigen::Vector3d q = t * clouds.source_axes.points[m.source];
    radius_sq += (q - centre).squaredNorm();
    sq += m.gap * m.gap;
    eq.addAcross(q - centre, clouds.target_axes.directions[m.target],
                 q - clouds.target_axes.points[m.target], huberWeight(m.gap));
  }
  Step step;
  step.rmse = std::sqrt(sq / n_pairs);
  // Rotation rows scaled by the cloud's radius so both blocks are lengths.
  const double scale = std::sqrt(radius_sq / n_pairs);
  Eigen::Matrix<double, 6, 1> s;
  s << Eigen::Vector3d::Constant(1.0 / std::max(scale, 1e-6)), Eigen::Vector3d::Ones();
  const Eigen::Matrix<double, 6, 6> An = s.asDiagonal() * eq.A * s.asDiagonal();
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> es(An);
  step.conditioning = es.eigenvalues()(0) / std::max(es.eigenvalues()(5), 1e-12);
  step.x = eq.A.ldlt().solve(eq.b);
  const double angle = step.x.head<3>().norm();
  if (angle > 0)
    step.transform.linear() = Eigen::AngleAxisd(angle, step.x.head<3>() / angle).toRotationMatrix();
  step.transform.translation() = centre - step.transform.linear() * centre + step.x.tail<3>();
  return step;
}

// Point-to-plane ICP on one level, from r.transform; the source one level coarser than the
// target: a sparser source costs fewer searches and its averaged points are less noisy, the
// dense target keeps the planes sharp.
void alignLevel(IcpResult& r, const Pyramid& source_p, const Pyramid& target_p, int level,
                const IcpConfig& c) {
  const int levels = static_cast<int>(c.voxels_m.size());
  const Surface& source = source_p.levels[std::max(level - 1, 0)];
  const Surface& target = target_p.levels[level];
  if (source.size() < MIN_POINTS || target.size() < MIN_POINTS)
    throw Error(ErrorCode::EMPTY_INPUT, "ICP needs at least 10 points in each cloud");
  const modeling::PointIndex index(target.points);
  // Axis pairs only where the estimates are meant to be read: at the finest level.
  const bool use_axes = c.axis_pairs && level == levels - 1 && !source_p.axes.points.empty() &&
                        !target_p.axes.points.empty();
  std::optional<modeling::PointIndex> axis_index;
  if (use_axes)
    axis_index.emplace(target_p.axes.points);
  const LevelPair clouds{source,
                         target,
                         index,
                         source_p.axes,
                         target_p.axes,
                         axis_index ? &*axis_index : nullptr,
                         c.distance_factor * c.voxels_m[level]};
  std::vector<Match> matches(source.size());
  std::vector<char> valid(source.size());
  r.converged = false;
  int small_steps = 0;
  // Coarse levels only have to hand over to the next: their steps scale with the voxel.
  const double scale = c.voxels_m[level] / c.voxels_m.back();
  for (int it = 0; it < c.max_iterations; ++it) {
    ++r.iterations;
    Pairs pairs = pairUp(clouds, r.transform, c, matches, valid);
    r.overlap = pairs.overlap;
    if (pairs.used.size() + pairs.axes.size() < MIN_PAIRS)
      throw Error(ErrorCode::EMPTY_INPUT, "ICP: the clouds do not overlap at the guess");
    trimPairs(pairs.used, c.trim);
    const Step step = solveStep(clouds, pairs, r.transform, c);
    r.rmse = step.rmse;
    r.conditioning = step.conditioning;
    if (!step.x.allFinite())
      break;
    r.transform = step.transform * r.transform;
    const double angle = step.x.head<3>().norm();
    const double shift = step.x.tail<3>().norm();
    if (angle < scale * c.min_rotation_step_deg * DEG && shift < scale * c.min_translation_step_m) {
      r.converged = true;
      break;
    }
    small_steps = angle < CYCLE_STEP_FACTOR * scale * c.min_rotation_step_deg * DEG &&
                          shift < CYCLE_STEP_FACTOR * scale * c.min_translation_step_m
                      ? small_steps + 1
                      : 0;
    if (small_steps >= CYCLE_STEPS) {
      r.converged = true;
      break;
    }
  }
}

}  // namespace

IcpResult alignPyramids(const Pyramid& source_p, const Pyramid& target_p,
                        const Eigen::Isometry3d& guess, const IcpConfig& c, int first_level,
                        int last_level) {
  c.validate();
  const int levels = static_cast<int>(c.voxels_m.size());
  if (source_p.levels.size() != c.voxels_m.size() || target_p.levels.size() != c.voxels_m.size())
    throw Error(ErrorCode::INVALID_ARGUMENT, "ICP: pyramids do not match the configured levels");
  if (last_level < 0 || last_level >= levels)
    last_level = levels - 1;
  first_level = std::clamp(first_level, 0, last_level);
  IcpResult r;
  r.transform = guess;
  for (int level = first_level; level <= last_level; ++level)
    alignLevel(r, source_p, target_p, level, c);
  return r;
}

IcpResult alignPointToPlane(const Points& source, const Points& target,
                            const Eigen::Isometry3d& guess, const IcpConfig& c) {
  c.validate();
  if (source.size() < 10 || target.size() < 10)
    throw Error(ErrorCode::EMPTY_INPUT, "ICP needs at least 10 points in each cloud");
  return alignPyramids(makePyramid(source, {}, c.voxels_m, c.normal_neighbors),
                       makePyramid(target, {}, c.voxels_m, c.normal_neighbors), guess, c);
}

}  // namespace registration
}  // namespace dormant_tree_modeling
