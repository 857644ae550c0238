#include <algorithm>
#include <cmath>
#include <limits>

#include "dormant_tree_modeling/modeling/trunk_model.h"

namespace dormant_tree_modeling {
namespace modeling {

Centerline::Centerline(std::vector<Eigen::Vector3d> vertices) : vertices_(std::move(vertices)) {
  cumulative_.push_back(0.0);
  rising_ = vertices_.size() >= 2;
  for (std::size_t i = 1; i < vertices_.size(); ++i) {
    const Eigen::Vector3d ab = vertices_[i] - vertices_[i - 1];
    const double length = ab.norm();
    cumulative_.push_back(cumulative_.back() + length);
    // Zero-length segments are kept (indices match the vertices) and never chosen.
    Segment seg;
    seg.direction = length > 0.0 ? Eigen::Vector3d(ab / length) : Eigen::Vector3d::Zero();
    seg.length = length;
    segments_.push_back(seg);
    rising_ = rising_ && vertices_[i].z() > vertices_[i - 1].z();
  }
}

double Centerline::segmentDistance2(std::size_t i, const Eigen::Vector3d& p, double* s) const {
  const Segment& seg = segments_[i];
  const Eigen::Vector3d w = p - vertices_[i];
  double t = w.dot(seg.direction);
  // Beyond the first and last vertex the end segments extend the line.
  if (i > 0)
    t = std::max(t, 0.0);
  if (i + 1 < segments_.size())
    t = std::min(t, seg.length);
  *s = cumulative_[i] + t;
  return (w - t * seg.direction).squaredNorm();
}

double Centerline::project(const Eigen::Vector3d& p, double* distance) const {
  // Projection is the inner loop of the trunk region, the point classes and the branch step,
  // over every point. The answer is the first segment (in index order) at the least distance.
  double best_d2 = std::numeric_limits<double>::infinity(), best_s = 0.0;
  std::size_t best_i = 0;
  const std::size_t n = segments_.size();
  const auto consider = [&](std::size_t i) {
    if (segments_[i].length <= 0.0)
      return;
    double s = 0.0;
    const double d2 = segmentDistance2(i, p, &s);
    if (d2 < best_d2 || (d2 == best_d2 && i < best_i)) {
      best_d2 = d2;
      best_s = s;
      best_i = i;
    }
  };
  if (!rising_ || n < 4) {
    for (std::size_t i = 0; i < n; ++i)
      consider(i);
  } else {
    // A rising polyline: an interior segment lies between its vertices' heights, so one whose
    // height range is farther from p than the best distance so far cannot be closer. Start at
    // p's height and walk down and up until that is so; the end segments (extended lines) are
    // always measured.
    consider(0);
    consider(n - 1);
    const auto above =
        std::upper_bound(vertices_.begin() + 1, vertices_.end() - 1, p.z(),
                         [](double z, const Eigen::Vector3d& v) { return z < v.z(); });
    const std::size_t start = static_cast<std::size_t>(above - vertices_.begin()) - 1;
    for (std::size_t i = std::min(start, n - 2); i >= 1; --i) {
      const double gap = p.z() - vertices_[i + 1].z();
      if (gap > 0.0 && gap * gap > best_d2)
        break;
      consider(i);
    }
    for (std::size_t i = std::max<std::size_t>(start + 1, 1); i + 1 < n; ++i) {
      const double gap = vertices_[i].z() - p.z();
      if (gap > 0.0 && gap * gap > best_d2)
        break;
      consider(i);
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
