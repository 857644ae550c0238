#include <Eigen/Dense>
#include <cmath>

#include "dormant_tree_modeling/modeling/geometry_fit.h"
#include "dormant_tree_modeling/common/random.h"

namespace dormant_tree_modeling {
namespace modeling {

namespace {

void basis(const Eigen::Vector3d& a, Eigen::Vector3d& u, Eigen::Vector3d& v) {
  u = a.unitOrthogonal();
  v = a.cross(u);
}

/// Fills length, centre (middle of the extent), and error statistics of c over pts.
void finish(Cylinder& c, const Points& pts) {
  double lo = 1e300, hi = -1e300, sq = 0.0, abs_err = 0.0, d2 = 0.0;
  for (const auto& p : pts) {
    const double t = (p - c.center).dot(c.axis);
    lo = std::min(lo, t);
    hi = std::max(hi, t);
    const double d = axisDistance(c, p);
    sq += (d - c.radius) * (d - c.radius);
    abs_err += std::abs(d - c.radius);
    d2 += d * d;
  }
  const double n = static_cast<double>(pts.size());
  c.center += 0.5 * (lo + hi) * c.axis;
  c.length = hi - lo;
  c.rms = std::sqrt(sq / n);
  c.mean_abs_error = abs_err / n;
  c.mean_sq_distance = d2 / n;
}

}  // namespace

double axisDistance(const Cylinder& c, const Eigen::Vector3d& p) {
  const Eigen::Vector3d w = p - c.center;
  return (w - w.dot(c.axis) * c.axis).norm();
}

Eigen::Vector3d principalAxis(const Points& pts, Eigen::Vector3d* centroid, Eigen::Vector3d* eigenvalues) {
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : pts) mean += p;
  mean /= static_cast<double>(std::max<std::size_t>(1, pts.size()));
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (const auto& p : pts) cov += (p - mean) * (p - mean).transpose();
  cov /= static_cast<double>(std::max<std::size_t>(1, pts.size()));
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
  if (centroid) *centroid = mean;
  if (eigenvalues) *eigenvalues = es.eigenvalues();
  return es.eigenvectors().col(2);
}

std::optional<Cylinder> fitCylinder(const Points& pts, const Eigen::Vector3d& axis_guess, bool fixed_axis) {
  if (pts.size() < 6) return std::nullopt;
  Eigen::Vector3d a = axis_guess.normalized();
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (const auto& p : pts) mean += p;
  mean /= static_cast<double>(pts.size());
  Eigen::Vector3d u, v;
  basis(a, u, v);
  Points2 plane;
  plane.reserve(pts.size());
  for (const auto& p : pts) plane.emplace_back((p - mean).dot(u), (p - mean).dot(v));
  const auto circle = fitCircle(plane);
  if (!circle) return std::nullopt;
  Eigen::Vector3d c = mean + circle->center.x() * u + circle->center.y() * v;
  double r = circle->radius;
  if (!fixed_axis) {
    // Gauss-Newton on (centre shift in the plane, axis tilt, radius).
    for (int it = 0; it < 30; ++it) {
      basis(a, u, v);
      Eigen::Matrix<double, 5, 5> JtJ = Eigen::Matrix<double, 5, 5>::Zero();
      Eigen::Matrix<double, 5, 1> Jtr = Eigen::Matrix<double, 5, 1>::Zero();
      for (const auto& p : pts) {
        const Eigen::Vector3d w = p - c;
        const double t = w.dot(a);
        const Eigen::Vector3d radial = w - t * a;
        const double d = radial.norm();
        if (d < 1e-12) continue;
        const Eigen::Vector3d n = radial / d;
        // Derivatives of the distance: centre shift along u, v; axis tilt towards u, v; radius.
        Eigen::Matrix<double, 5, 1> J;
        J << -n.dot(u), -n.dot(v), -t * n.dot(u), -t * n.dot(v), -1.0;
        JtJ += J * J.transpose();
        Jtr += J * (d - r);
      }
      JtJ.diagonal() *= 1.0 + 1e-6;
      const Eigen::Matrix<double, 5, 1> step = JtJ.ldlt().solve(-Jtr);
      if (!step.allFinite()) break;
      c += step(0) * u + step(1) * v;
      a = (a + step(2) * u + step(3) * v).normalized();
      r += step(4);
      if (step.norm() < 1e-10) break;
    }
  }
  if (!(r > 0.0) || !c.allFinite() || !a.allFinite()) return std::nullopt;
  if (a.dot(axis_guess) < 0.0) a = -a;
  Cylinder cyl;
  cyl.axis = a;
  cyl.center = c + (mean - c).dot(a) * a;
  cyl.radius = r;
  finish(cyl, pts);
  return cyl;
}

std::optional<Cylinder> ransacCylinder(const Points& pts, const Eigen::Vector3d& axis_guess,
                                       const CylinderRansacOptions& o, std::vector<int>* inliers) {
  if (pts.size() < 6) return std::nullopt;
  Rng rng(o.seed);
  const Eigen::Vector3d guess = axis_guess.normalized();
  std::vector<Eigen::Vector3d> axes{guess};
  const Eigen::Vector3d pca = principalAxis(pts);
  const Eigen::Vector3d pca_signed = pca.dot(guess) < 0.0 ? Eigen::Vector3d(-pca) : pca;
  if (std::acos(std::min(1.0, pca_signed.dot(guess))) <= o.max_axis_deviation) axes.push_back(pca_signed);
  Eigen::Vector3d u, v;
  basis(guess, u, v);
  for (int i = 0; i < o.axis_candidates; ++i) {
    const double tilt = o.max_axis_deviation * std::sqrt(rng.uniform());
    const double az = rng.uniform(0.0, 2.0 * M_PI);
    axes.push_back((std::cos(tilt) * guess + std::sin(tilt) * (std::cos(az) * u + std::sin(az) * v)).normalized());
  }
  CircleRansacOptions co;
  co.threshold = o.threshold;
  co.iterations = o.circle_iterations;
  co.min_radius = o.min_radius;
  co.max_radius = o.max_radius;
  std::vector<int> best_in;
  Eigen::Vector3d best_axis = guess;
  for (std::size_t k = 0; k < axes.size(); ++k) {
    basis(axes[k], u, v);
    Points2 plane;
    plane.reserve(pts.size());
    for (const auto& p : pts) plane.emplace_back(p.dot(u), p.dot(v));
    co.seed = o.seed * 1000003ULL + k;
    std::vector<int> in;
    if (!ransacCircle(plane, co, &in)) continue;
    if (in.size() > best_in.size()) {
      best_in = in;
      best_axis = axes[k];
    }
  }
  if (best_in.size() < 6) return std::nullopt;
  Points sub;
  for (const int i : best_in) sub.push_back(pts[i]);
  auto cyl = fitCylinder(sub, best_axis);
  // The refinement may leave the radius bounds or the axis cone: fall back to a fixed axis.
  if (!cyl || cyl->radius < o.min_radius || cyl->radius > o.max_radius ||
      std::acos(std::min(1.0, std::abs(cyl->axis.dot(guess)))) > o.max_axis_deviation) {
    cyl = fitCylinder(sub, best_axis, true);
  }
  if (!cyl || cyl->radius < o.min_radius || cyl->radius > o.max_radius) return std::nullopt;
  if (inliers) {
    inliers->clear();
    for (std::size_t i = 0; i < pts.size(); ++i) {
      if (std::abs(axisDistance(*cyl, pts[i]) - cyl->radius) < o.threshold) inliers->push_back(static_cast<int>(i));
    }
  }
  return cyl;
}

double noiseCorrectedRadius(const Cylinder& c, const Points& pts, double sigma, double band, double min_radius) {
  double sum = 0.0;
  int n = 0;
  for (const auto& p : pts) {
    // One-sided: every point inside the fitted surface counts, so the band is not centred on a
    // radius the noise already inflated.
    const double d = axisDistance(c, p);
    if (d < c.radius + band) {

      sum += d * d;
      ++n;
    }
  }
  if (n == 0) return c.radius;
  const double r2 = sum / n - sigma * sigma;
  return std::max(min_radius, std::sqrt(std::max(0.0, r2)));
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
