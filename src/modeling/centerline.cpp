#include <algorithm>
#include <cmath>
#include <limits>

#include "dormant_tree_modeling/modeling/trunk_model.h"

namespace dormant_tree_modeling {
namespace modeling {

Centerline::Centerline(std::vector<Eigen::Vector3d> vertices) : vertices_(std::move(vertices)) {
  cumulative_.push_back(0.0);
  for (std::size_t i = 1; i < vertices_.size(); ++i) {
    const Eigen::Vector3d ab = vertices_[i] - vertices_[i - 1];
    const double length = ab.norm();
    cumulative_.push_back(cumulative_.back() + length);
    // Zero-length segments are kept (indices match the vertices) and never chosen.
    Segment seg;
    seg.direction = length > 0.0 ? Eigen::Vector3d(ab / length) : Eigen::Vector3d::Zero();
    seg.length = length;
    segments_.push_back(seg);
  }
}

double Centerline::project(const Eigen::Vector3d& p, double* distance) const {
  // Squared distances and unit directions: projection is the inner loop of the trunk region,
  // the point classes and the branch step, over every point and every segment.
  double best_d2 = std::numeric_limits<double>::infinity(), best_s = 0.0;
  const std::size_t n = segments_.size();
  for (std::size_t i = 0; i < n; ++i) {
    const Segment& seg = segments_[i];
    if (seg.length <= 0.0)
      continue;
    const Eigen::Vector3d w = p - vertices_[i];
    double t = w.dot(seg.direction);
    // Beyond the first and last vertex the end segments extend the line.
    if (i > 0)
      t = std::max(t, 0.0);
    if (i + 1 < n)
      t = std::min(t, seg.length);
    const double d2 = (w - t * seg.direction).squaredNorm();
    if (d2 < best_d2) {
      best_d2 = d2;
      best_s = cumulative_[i] + t;
    }
  }
  if (distance)
    *distance = std::sqrt(best_d2);
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
