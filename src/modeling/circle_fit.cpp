#include <Eigen/Dense>
#include <cmath>
#include <limits>

#include "dormant_tree_modeling/common/random.h"
#include "dormant_tree_modeling/modeling/geometry_fit.h"

namespace dormant_tree_modeling {
namespace modeling {

namespace {
constexpr int HOPE_CHECK = 64;  // points between checks that a RANSAC hypothesis can still win
constexpr double INFINITY_BAND = std::numeric_limits<double>::infinity();
constexpr int ROBUST_MIN_POINTS = 6;   // points inside the band a robust circle needs
constexpr int ROBUST_ITERATIONS = 20;  // reweighting rounds of robustCircle at most

struct GeometricStep {
  Eigen::Vector3d step = Eigen::Vector3d::Zero();  ///< centre x, y and radius change
  int used = 0;                                    ///< points with a weight
};

/// One Gauss-Newton step of the geometric circle fit on the points less `offset`, each point
/// weighted by Tukey's biweight of its residual over `band` (an infinite band: least squares).
GeometricStep geometricStep(const Points2& pts, const Eigen::Vector2d& offset, const Circle& c,
                            double band) {
  Eigen::Matrix3d JtJ = Eigen::Matrix3d::Zero();
  Eigen::Vector3d Jtr = Eigen::Vector3d::Zero();
  GeometricStep out;
  for (const auto& p : pts) {
    const Eigen::Vector2d q = p - offset - c.center;
    const double d = q.norm();
    const double e = d - c.radius;
    if (d < 1e-12 || !(std::abs(e) < band))
      continue;
    const double u = std::isinf(band) ? 0.0 : e / band;
    const double w = (1.0 - u * u) * (1.0 - u * u);
    const Eigen::Vector3d J(-q.x() / d, -q.y() / d, -1.0);
    JtJ += w * J * J.transpose();
    Jtr += w * J * e;
    ++out.used;
  }
  out.step = JtJ.ldlt().solve(-Jtr);
  return out;
}
}  // namespace

std::optional<Circle> circleThrough(const Eigen::Vector2d& a, const Eigen::Vector2d& b,
                                    const Eigen::Vector2d& c) {
  const double d =
      2.0 * (a.x() * (b.y() - c.y()) + b.x() * (c.y() - a.y()) + c.x() * (a.y() - b.y()));
  const double scale = std::max({(b - a).squaredNorm(), (c - a).squaredNorm(), 1e-30});
  if (std::abs(d) < 1e-9 * scale)
    return std::nullopt;
  const double a2 = a.squaredNorm(), b2 = b.squaredNorm(), c2 = c.squaredNorm();
  Circle circle;
  circle.center =
      Eigen::Vector2d((a2 * (b.y() - c.y()) + b2 * (c.y() - a.y()) + c2 * (a.y() - b.y())) / d,
                      (a2 * (c.x() - b.x()) + b2 * (a.x() - c.x()) + c2 * (b.x() - a.x())) / d);
  circle.radius = (a - circle.center).norm();
  return circle;
}

std::optional<Circle> fitCircle(const Points2& pts) {
  const int n = static_cast<int>(pts.size());
  if (n < 3)
    return std::nullopt;
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& p : pts)
    mean += p;
  mean /= n;
  // Kasa: x^2 + y^2 + D x + E y + F = 0, linear least squares on centred points (normal
  // equations: 3 unknowns, no n x 3 matrix on the heap; centring keeps them well conditioned).
  Eigen::Matrix3d AtA = Eigen::Matrix3d::Zero();
  Eigen::Vector3d Atb = Eigen::Vector3d::Zero();
  for (const auto& p : pts) {
    const Eigen::Vector2d q = p - mean;
    const Eigen::Vector3d row(q.x(), q.y(), 1.0);
    AtA.noalias() += row * row.transpose();
    Atb -= row * q.squaredNorm();
  }
  const Eigen::Vector3d s = AtA.ldlt().solve(Atb);
  if (!s.allFinite())
    return std::nullopt;
  Circle c;
  c.center = Eigen::Vector2d(-0.5 * s(0), -0.5 * s(1));
  const double r2 = c.center.squaredNorm() - s(2);
  if (!(r2 > 0.0) || !std::isfinite(r2))
    return std::nullopt;
  c.radius = std::sqrt(r2);
  // Geometric refinement: minimise sum (|q - c| - r)^2.
  for (int it = 0; it < 20; ++it) {
    const Eigen::Vector3d step = geometricStep(pts, mean, c, INFINITY_BAND).step;
    if (!step.allFinite())
      break;
    c.center += step.head<2>();
    c.radius += step(2);
    if (step.norm() < 1e-8)
      break;
  }
  if (!(c.radius > 0.0) || !c.center.allFinite())
    return std::nullopt;
  c.center += mean;
  return c;
}

std::optional<Circle> robustCircle(const Points2& pts, const Circle& start, double band) {
  if (!(band > 0.0) || !start.center.allFinite() || !(start.radius > 0.0))
    return std::nullopt;
  Circle c = start;
  for (int it = 0; it < ROBUST_ITERATIONS; ++it) {
    const GeometricStep s = geometricStep(pts, Eigen::Vector2d::Zero(), c, band);
    if (s.used < ROBUST_MIN_POINTS || !s.step.allFinite())
      return std::nullopt;
    c.center += s.step.head<2>();
    c.radius += s.step(2);
    if (s.step.norm() < 1e-8)
      break;
  }
  if (!(c.radius > 0.0) || !c.center.allFinite())
    return std::nullopt;
  return c;
}

namespace {
bool withinBounds(const Circle& c, const CircleRansacConfig& o) {
  return c.radius >= o.min_radius && c.radius <= o.max_radius &&
         c.center.norm() <= o.max_center_offset;
}
}  // namespace

std::optional<Circle> ransacCircle(const Points2& pts, const CircleRansacConfig& o,
                                   std::vector<int>* inliers) {
  const int n = static_cast<int>(pts.size());
  if (n < 3)
    return std::nullopt;
  Rng rng(o.seed);
  std::optional<Circle> best;
  int best_count = 0;
  double best_cost = 0.0;
  for (int it = 0; it < o.iterations; ++it) {
    const int i = rng.uniformInt(0, n - 1), j = rng.uniformInt(0, n - 1),
              k = rng.uniformInt(0, n - 1);
    if (i == j || j == k || i == k)
      continue;
    const auto c = circleThrough(pts[i], pts[j], pts[k]);
    if (!c || !withinBounds(*c, o))
      continue;
    // Inliers from squared distances (a root only for the inliers' cost); a hypothesis that can
    // no longer reach the best count is left early. Same choice as scoring every point.
    const double inner = c->radius - o.threshold;
    const double inner2 = inner > 0.0 ? inner * inner : -1.0;
    const double outer2 = (c->radius + o.threshold) * (c->radius + o.threshold);
    int count = 0;
    double cost = 0.0;
    bool hopeless = false;
    for (int start = 0; start < n && !hopeless; start += HOPE_CHECK) {
      const int end = std::min(n, start + HOPE_CHECK);
      for (int m = start; m < end; ++m) {
        const double d2 = (pts[m] - c->center).squaredNorm();
        if (d2 > inner2 && d2 < outer2) {
          const double e = std::abs(std::sqrt(d2) - c->radius);
          if (e < o.threshold) {
            ++count;
            cost += e;
          }
        }
      }
      hopeless = count + (n - end) < best_count;
    }
    if (hopeless)
      continue;
    if (count > best_count || (count == best_count && cost < best_cost)) {
      best = c;
      best_count = count;
      best_cost = cost;
    }
  }
  if (!best)
    return std::nullopt;
  // Refine on the inliers, twice (inliers of the refined circle), within the radius bounds.
  for (int round = 0; round < 2; ++round) {
    Points2 sub;
    for (const auto& p : pts) {
      if (std::abs((p - best->center).norm() - best->radius) < o.threshold)
        sub.push_back(p);
    }
    const auto refined = fitCircle(sub);
    if (!refined || !withinBounds(*refined, o))
      break;
    best = refined;
  }
  if (inliers) {
    inliers->clear();
    for (int i = 0; i < n; ++i) {
      if (std::abs((pts[i] - best->center).norm() - best->radius) < o.threshold)
        inliers->push_back(i);
    }
  }
  return best;
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
