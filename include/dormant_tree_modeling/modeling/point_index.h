#pragma once

#include <memory>
#include <vector>

#include "dormant_tree_modeling/modeling/geometry_fit.h"

namespace dormant_tree_modeling {
namespace modeling {

/// @brief Nearest-neighbour queries over a fixed point set (a kd-tree; PCL stays in the .cpp).
class PointIndex {
 public:
  /// @param pts points to index; copied
  explicit PointIndex(const Points& pts);
  ~PointIndex();
  PointIndex(const PointIndex&) = delete;
  PointIndex& operator=(const PointIndex&) = delete;

  /// @brief Indices of the k nearest points to q (fewer when the set is smaller), nearest first.
  std::vector<int> nearest(const Eigen::Vector3d& q, int k) const;

  /// @brief The nearest point to q, or -1 when the set is empty; allocation-free, for hot loops
  /// (ICP runs it for every point in every iteration, on all threads).
  /// @param squared_distance optional: receives its squared distance
  int nearestOne(const Eigen::Vector3d& q, float* squared_distance = nullptr) const;

  /// @brief Indices of all points within radius of q.
  std::vector<int> within(const Eigen::Vector3d& q, double radius) const;

  /// @brief Number of points within radius of q, stopping once `limit` are found.
  int countWithin(const Eigen::Vector3d& q, double radius, int limit) const;

  std::size_t size() const { return size_; }

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::size_t size_;
};

/// @brief Euclidean clustering: connected components of points closer than `tolerance`.
/// @param pts points
/// @param tolerance link distance (m)
/// @param min_size clusters smaller than this are returned in `small` (never silently dropped)
/// @param small optional: receives the indices of points of clusters below min_size
/// @returns clusters (point indices), largest first
std::vector<std::vector<int>> euclideanClusters(const Points& pts, double tolerance, int min_size,
                                                std::vector<int>* small = nullptr);

}  // namespace modeling
}  // namespace dormant_tree_modeling
