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

}  // namespace

void IcpConfig::validate() const {
  auto require = [](bool ok, const char* m) {
    if (!ok)
      throw Error(ErrorCode::INVALID_ARGUMENT, std::string("ICP: ") + m);
  };
  require(!voxels.empty(), "needs at least one level");
  for (const double v : voxels)
    require(v > 0, "voxel sizes must be > 0");
  require(distance_factor > 0, "distance_factor must be > 0");
  require(max_iterations > 0, "max_iterations must be > 0");
  require(trim > 0 && trim <= 1, "trim must be in (0, 1]");
  require(huber > 0, "huber must be > 0");
  require(normal_neighbors >= 5, "normal_neighbors must be >= 5");
  require(across_cos >= -1 && across_cos <= 1, "across_cos must be in [-1, 1]");
  require(overlap_distance > 0, "overlap_distance must be > 0");
  require(axis_max_angle_deg > 0 && axis_max_angle_deg < 90,
          "axis_max_angle_deg must be in (0, 90)");
  require(min_rotation_step > 0 && min_translation_step > 0, "convergence steps must be > 0");
}

IcpResult alignPyramids(const Pyramid& source_p, const Pyramid& target_p,
                        const Eigen::Isometry3d& guess, const IcpConfig& c, int first_level,
                        int last_level) {
  c.validate();
  const int levels = static_cast<int>(c.voxels.size());
  if (source_p.levels.size() != c.voxels.size() || target_p.levels.size() != c.voxels.size())
    throw Error(ErrorCode::INVALID_ARGUMENT, "ICP: pyramids do not match the configured levels");
  if (last_level < 0 || last_level >= levels)
    last_level = levels - 1;
  first_level = std::clamp(first_level, 0, last_level);
  IcpResult r;
  r.transform = guess;
  for (int level = first_level; level <= last_level; ++level) {
    // The source one level coarser than the target: a sparser source costs fewer searches and
    // its averaged points are less noisy; the dense target keeps the planes sharp.
    const Surface& source = source_p.levels[std::max(level - 1, 0)];
    const Surface& target = target_p.levels[level];
    if (source.size() < 10 || target.size() < 10)
      throw Error(ErrorCode::EMPTY_INPUT, "ICP needs at least 10 points in each cloud");
    const modeling::PointIndex index(target.points);
    const double limit = c.distance_factor * c.voxels[level];
    // Axis pairs only where the estimates are meant to be read: at the finest level.
    const bool use_axes = c.axis_pairs && level == levels - 1 && !source_p.axes.points.empty() &&
                          !target_p.axes.points.empty();
    std::optional<modeling::PointIndex> axis_index;
    if (use_axes)
      axis_index.emplace(target_p.axes.points);
    std::vector<Match> matches(source.size());
    std::vector<char> valid(source.size());
    r.converged = false;
    int small_steps = 0;
    for (int it = 0; it < c.max_iterations; ++it) {
      ++r.iterations;
      const Eigen::Matrix3d rot = r.transform.linear();
      parallelFor(static_cast<int>(source.size()), [&](int i) {
        valid[i] = 0;
        const Eigen::Vector3d p = r.transform * source.points[i];
        const int j = index.nearestOne(p);
        if (j < 0)
          return;
        const Eigen::Vector3d& n = target.normals[j];
        if (n.isZero())
          return;
        const Eigen::Vector3d d = p - target.points[j];
        if (d.squaredNorm() > limit * limit)
          return;
        const Eigen::Vector3d& vt = target.view_dirs[j];
        const bool across = !vt.isZero() && !source.view_dirs[i].isZero() &&
                            (rot * source.view_dirs[i]).dot(vt) < c.across_cos;
        const double ray_gap = across ? (d - d.dot(vt) * vt).norm() : 0.0;
        matches[i] = {i, j, across ? ray_gap : d.dot(n), across ? ray_gap : d.norm(), across};
        valid[i] = 1;
      });
      std::vector<Match> used;
      std::size_t close = 0;
      for (std::size_t i = 0; i < source.size(); ++i) {
        if (!valid[i])
          continue;
        close += matches[i].gap <= c.overlap_distance;
        // With axis pairs, opposite halves say where the branch is through its axes only.
        if (!(use_axes && matches[i].across))
          used.push_back(matches[i]);
      }
      r.overlap = static_cast<double>(close) / source.size();
      std::vector<AxisMatch> axis_used;
      if (use_axes) {
        axis_used = matchAxes(source_p.axes, target_p.axes, *axis_index, r.transform, limit, c);
        const std::size_t axis_keep = static_cast<std::size_t>(c.trim * axis_used.size());
        if (axis_keep < axis_used.size()) {
          std::nth_element(axis_used.begin(), axis_used.begin() + axis_keep, axis_used.end(),
                           [](const AxisMatch& a, const AxisMatch& b) { return a.gap < b.gap; });
          axis_used.resize(axis_keep);
        }
      }
      if (used.size() + axis_used.size() < 10)
        throw Error(ErrorCode::EMPTY_INPUT, "ICP: the clouds do not overlap at the guess");
      const std::size_t keep = std::min(
          used.size(), std::max<std::size_t>(10, static_cast<std::size_t>(c.trim * used.size())));
      if (keep > 0) {
        std::nth_element(used.begin(), used.begin() + (keep - 1), used.end(),
                         [](const Match& a, const Match& b) {
                           return std::abs(a.residual) < std::abs(b.residual);
                         });
      }
      used.resize(keep);
      // Linearised point-to-plane step (small rotation w, translation t), Huber-weighted.
      Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
      Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
      // Rotations about the matched points' centroid keep the two halves of the system on
      // one scale (the conditioning measure needs that).
      Eigen::Vector3d centre = Eigen::Vector3d::Zero();
      for (const auto& m : used)
        centre += r.transform * source.points[m.source];
      for (const auto& m : axis_used)
        centre += r.transform * source_p.axes.points[m.source];
      const double pairs = static_cast<double>(used.size() + axis_used.size());
      centre /= pairs;
      // One linearised row: residual e along unit n at the centred point p, weight w.
      auto addRow = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& n, double e, double w) {
        Eigen::Matrix<double, 6, 1> J;
        J << p.cross(n), n;
        A += w * J * J.transpose();
        b -= w * J * e;
      };
      // The offset d counted only across a line of direction dir (a ray, a branch axis).
      auto addAcross = [&](const Eigen::Vector3d& p, const Eigen::Vector3d& dir,
                           const Eigen::Vector3d& d, double w) {
        Eigen::Vector3d u, v;
        planeBasis(dir, u, v);
        addRow(p, u, d.dot(u), w);
        addRow(p, v, d.dot(v), w);
      };
      auto huberWeight = [&](double e) {
        return std::abs(e) <= c.huber ? 1.0 : c.huber / std::abs(e);
      };
      double sq = 0, radius_sq = 0;
      for (const auto& m : used) {
        const Eigen::Vector3d q = r.transform * source.points[m.source];
        const Eigen::Vector3d p = q - centre;
        radius_sq += p.squaredNorm();
        const double w = huberWeight(m.residual);
        sq += m.residual * m.residual;
        if (!m.across) {
          addRow(p, target.normals[m.target], m.residual, w);
          continue;
        }
        // Seen from opposite sides, the two points lie on opposite halves of a branch: only
        // the offset across the target's ray says how far apart the branch axes are.
        addAcross(p, target.view_dirs[m.target], q - target.points[m.target], w);
      }
      for (const auto& m : axis_used) {
        const Eigen::Vector3d q = r.transform * source_p.axes.points[m.source];
        radius_sq += (q - centre).squaredNorm();
        sq += m.gap * m.gap;
        addAcross(q - centre, target_p.axes.directions[m.target],
                  q - target_p.axes.points[m.target], huberWeight(m.gap));
      }
      r.rmse = std::sqrt(sq / pairs);
      {
        // Rotation rows scaled by the cloud's radius so both blocks are lengths.
        const double scale = std::sqrt(radius_sq / pairs);
        Eigen::Matrix<double, 6, 1> s;
        s << Eigen::Vector3d::Constant(1.0 / std::max(scale, 1e-6)), Eigen::Vector3d::Ones();
        const Eigen::Matrix<double, 6, 6> An = s.asDiagonal() * A * s.asDiagonal();
        const Eigen::SelfAdjointEigenSolver<Eigen::Matrix<double, 6, 6>> es(An);
        r.conditioning = es.eigenvalues()(0) / std::max(es.eigenvalues()(5), 1e-12);
      }
      const Eigen::Matrix<double, 6, 1> x = A.ldlt().solve(b);
      if (!x.allFinite())
        break;
      Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
      const double angle = x.head<3>().norm();
      if (angle > 0)
        step.linear() = Eigen::AngleAxisd(angle, x.head<3>() / angle).toRotationMatrix();
      step.translation() = centre - step.linear() * centre + x.tail<3>();
      r.transform = step * r.transform;
      // Coarse levels only have to hand over to the next: their steps scale with the voxel.
      const double scale = c.voxels[level] / c.voxels.back();
      if (angle < scale * c.min_rotation_step * DEG &&
          x.tail<3>().norm() < scale * c.min_translation_step) {
        r.converged = true;
        break;
      }
      // Hard nearest-neighbour pairs can flip back and forth between two near-equal poses; a
      // run of steps within ten times the limits is such a cycle, and as converged as it gets.
      small_steps = angle < 10 * scale * c.min_rotation_step * DEG &&
                            x.tail<3>().norm() < 10 * scale * c.min_translation_step
                        ? small_steps + 1
                        : 0;
      if (small_steps >= 4) {
        r.converged = true;
        break;
      }
    }
  }
  return r;
}

IcpResult alignPointToPlane(const Points& source, const Points& target,
                            const Eigen::Isometry3d& guess, const IcpConfig& c) {
  c.validate();
  if (source.size() < 10 || target.size() < 10)
    throw Error(ErrorCode::EMPTY_INPUT, "ICP needs at least 10 points in each cloud");
  return alignPyramids(makePyramid(source, {}, c.voxels, c.normal_neighbors),
                       makePyramid(target, {}, c.voxels, c.normal_neighbors), guess, c);
}

}  // namespace registration
}  // namespace dormant_tree_modeling
