#include "dormant_tree_modeling/simulation/primitives.h"

#include <Eigen/Geometry>
#include <cmath>

namespace dormant_tree_modeling {
namespace simulation {

std::optional<std::pair<double, Eigen::Vector3d>> intersect(const Ray& ray, const Frustum& f,
                                                            double t_min, double t_max) {
  const Eigen::Vector3d axis = f.b - f.a;
  const double length = axis.norm();
  if (length <= 0.0)
    return std::nullopt;
  const Eigen::Vector3d u = axis / length;
  const double k = (f.rb - f.ra) / length;  // radius slope along the axis
  const Eigen::Vector3d w0 = ray.origin - f.a;
  const double alpha = w0.dot(u);
  const double beta = ray.direction.dot(u);
  // radial^2 = (ra + k * along)^2 with along = alpha + s beta: a quadratic in s.
  const double c0 = f.ra + k * alpha;
  const double c1 = k * beta;
  const double qa = 1.0 - beta * beta - c1 * c1;
  const double qb = 2.0 * (w0.dot(ray.direction) - alpha * beta - c0 * c1);
  const double qc = w0.squaredNorm() - alpha * alpha - c0 * c0;
  double roots[2];
  int n = 0;
  if (std::abs(qa) < 1e-12) {
    if (std::abs(qb) < 1e-15)
      return std::nullopt;
    roots[n++] = -qc / qb;
  } else {
    const double disc = qb * qb - 4.0 * qa * qc;
    if (disc < 0.0)
      return std::nullopt;
    const double sq = std::sqrt(disc);
    // Numerically stable pair of roots.
    const double q = -0.5 * (qb + std::copysign(sq, qb));
    roots[n++] = q / qa;
    if (q != 0.0)
      roots[n++] = qc / q;
    if (n == 2 && roots[1] < roots[0])
      std::swap(roots[0], roots[1]);
  }
  for (int i = 0; i < n; ++i) {
    const double s = roots[i];
    if (!(s > t_min && s < t_max))
      continue;
    const double along = alpha + s * beta;
    if (along < 0.0 || along > length)
      continue;
    const double radius = f.ra + k * along;
    if (radius < 0.0)
      continue;  // the mirrored nappe of the cone
    const Eigen::Vector3d w = w0 + s * ray.direction;
    Eigen::Vector3d radial = w - along * u;
    const double rn = radial.norm();
    if (rn < 1e-12)
      continue;
    Eigen::Vector3d normal = (radial / rn - k * u).normalized();
    return std::make_pair(s, normal);
  }
  return std::nullopt;
}

std::optional<std::pair<double, Eigen::Vector3d>> intersect(const Ray& ray, const Sphere& s,
                                                            double t_min, double t_max) {
  const Eigen::Vector3d oc = ray.origin - s.c;
  const double b = oc.dot(ray.direction);
  const double c = oc.squaredNorm() - s.r * s.r;
  const double disc = b * b - c;
  if (disc < 0.0)
    return std::nullopt;
  const double sq = std::sqrt(disc);
  for (const double t : {-b - sq, -b + sq}) {
    if (t > t_min && t < t_max) {
      return std::make_pair(t, ((oc + t * ray.direction) / s.r).eval());
    }
  }
  return std::nullopt;
}

}  // namespace simulation
}  // namespace dormant_tree_modeling
