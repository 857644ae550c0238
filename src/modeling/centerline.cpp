#include <algorithm>
#include <limits>

#include "dormant_tree_modeling/modeling/trunk_model.h"

namespace dormant_tree_modeling {
namespace modeling {

Centerline::Centerline(std::vector<Eigen::Vector3d> vertices) : vertices_(std::move(vertices)) {
  cumulative_.push_back(0.0);
  for (std::size_t i = 1; i < vertices_.size(); ++i) {
    cumulative_.push_back(cumulative_.back() + (vertices_[i] - vertices_[i - 1]).norm());
  }
}

double Centerline::project(const Eigen::Vector3d& p, double* distance) const {
  double best_d = std::numeric_limits<double>::infinity(), best_s = 0.0;
  const std::size_t n = vertices_.size();
  for (std::size_t i = 0; i + 1 < n; ++i) {
    const Eigen::Vector3d ab = vertices_[i + 1] - vertices_[i];
    const double len2 = ab.squaredNorm();
    if (len2 <= 0.0)
      continue;
    double t = (p - vertices_[i]).dot(ab) / len2;
    // Beyond the first and last vertex the end segments extend the line.
    const double lo = i == 0 ? -std::numeric_limits<double>::infinity() : 0.0;
    const double hi = i + 2 == n ? std::numeric_limits<double>::infinity() : 1.0;
    t = std::clamp(t, lo, hi);
    const double d = (vertices_[i] + t * ab - p).norm();
    if (d < best_d) {
      best_d = d;
      best_s = cumulative_[i] + t * std::sqrt(len2);
    }
  }
  if (distance)
    *distance = best_d;
  return best_s;
}

std::size_t Centerline::segmentAt(double s) const {
  const auto it = std::upper_bound(cumulative_.begin(), cumulative_.end(), s);
  const std::size_t i =
      it == cumulative_.begin() ? 0 : static_cast<std::size_t>(it - cumulative_.begin()) - 1;
  return std::min(i, vertices_.size() - 2);
}

Eigen::Vector3d Centerline::pointAt(double s) const {
  const std::size_t i = segmentAt(s);
  const double len = cumulative_[i + 1] - cumulative_[i];
  const double t = len > 0.0 ? (s - cumulative_[i]) / len : 0.0;
  return vertices_[i] + t * (vertices_[i + 1] - vertices_[i]);
}

Eigen::Vector3d Centerline::directionAt(double s) const {
  const std::size_t i = segmentAt(s);
  return (vertices_[i + 1] - vertices_[i]).normalized();
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
