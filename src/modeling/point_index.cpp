#include "dormant_tree_modeling/modeling/point_index.h"

#include <array>

// FLANN's kd-tree directly: PCL's KdTreeFLANN sends every single query through FLANN's
// batch search, which opens an OpenMP region per query; called from our worker threads
// that cost more in futex calls than the search itself (6 M calls for one registration).
#include <flann/algorithms/dist.h>
#include <flann/algorithms/kdtree_single_index.h>
#include <flann/util/result_set.h>

#include <algorithm>

namespace dormant_tree_modeling {
namespace modeling {

struct PointIndex::Impl {
  std::vector<float> data;  // x y z per point, referenced by the index
  std::unique_ptr<flann::KDTreeSingleIndex<flann::L2_Simple<float>>> tree;
  flann::SearchParams params{flann::FLANN_CHECKS_UNLIMITED, 0.0f, false};

  std::array<float, 3> query(const Eigen::Vector3d& q) const {
    return {static_cast<float>(q.x()), static_cast<float>(q.y()), static_cast<float>(q.z())};
  }
};

PointIndex::PointIndex(const Points& pts) : impl_(new Impl), size_(pts.size()) {
  impl_->data.reserve(3 * pts.size());
  for (const auto& p : pts) {
    impl_->data.push_back(static_cast<float>(p.x()));
    impl_->data.push_back(static_cast<float>(p.y()));
    impl_->data.push_back(static_cast<float>(p.z()));
  }
  if (!pts.empty()) {
    const flann::Matrix<float> m(impl_->data.data(), pts.size(), 3);
    // Leaves of 15 points, as PCL builds it; reordering copies the data into tree order.
    impl_->tree = std::make_unique<flann::KDTreeSingleIndex<flann::L2_Simple<float>>>(
        m, flann::KDTreeSingleIndexParams(15));
    impl_->tree->buildIndex();
  }
}

PointIndex::~PointIndex() = default;

std::vector<int> PointIndex::nearest(const Eigen::Vector3d& q, int k) const {
  std::vector<int> idx;
  if (size_ == 0 || k <= 0)
    return idx;
  k = std::min<int>(k, static_cast<int>(size_));
  flann::KNNSimpleResultSet<float> result(static_cast<std::size_t>(k));
  const auto v = impl_->query(q);
  impl_->tree->findNeighbors(result, v.data(), impl_->params);
  std::vector<std::size_t> found(result.size());
  std::vector<float> dist(result.size());
  result.copy(found.data(), dist.data(), found.size(), true);
  idx.assign(found.begin(), found.end());
  return idx;
}

int PointIndex::nearestOne(const Eigen::Vector3d& q, float* squared_distance) const {
  if (size_ == 0)
    return -1;
  flann::KNNSimpleResultSet<float> result(1);
  const auto v = impl_->query(q);
  impl_->tree->findNeighbors(result, v.data(), impl_->params);
  if (result.size() < 1)
    return -1;
  std::size_t i = 0;
  float d = 0;
  result.copy(&i, &d, 1, false);
  if (squared_distance)
    *squared_distance = d;
  return static_cast<int>(i);
}

namespace {

/// FLANN's RadiusResultSet without its (distance, index) pairs and their copy: indices go
/// straight into the caller's vector, in the order the search finds them, as the set keeps them.
class IndexCollector : public flann::ResultSet<float> {
 public:
  IndexCollector(float squared_radius, std::vector<int>& out)
      : squared_radius_(squared_radius), out_(out) {}
  bool full() const override { return true; }
  void addPoint(float dist, std::size_t index) override {
    if (dist < squared_radius_)
      out_.push_back(static_cast<int>(index));
  }
  float worstDist() const override { return squared_radius_; }

 private:
  float squared_radius_;
  std::vector<int>& out_;
};

}  // namespace

std::vector<int> PointIndex::within(const Eigen::Vector3d& q, double radius) const {
  std::vector<int> idx;
  if (size_ == 0)
    return idx;
  IndexCollector result(static_cast<float>(radius * radius), idx);
  const auto v = impl_->query(q);
  impl_->tree->findNeighbors(result, v.data(), impl_->params);
  return idx;
}

int PointIndex::countWithin(const Eigen::Vector3d& q, double radius, int limit) const {
  if (size_ == 0 || limit <= 0)
    return 0;
  flann::KNNRadiusResultSet<float> result(static_cast<float>(radius * radius),
                                          static_cast<std::size_t>(limit));
  const auto v = impl_->query(q);
  impl_->tree->findNeighbors(result, v.data(), impl_->params);
  return static_cast<int>(result.size());
}

std::vector<std::vector<int>> euclideanClusters(const Points& pts, double tolerance, int min_size,
                                                std::vector<int>* small) {
  std::vector<std::vector<int>> clusters;
  if (small)
    small->clear();
  if (pts.empty())
    return clusters;
  const PointIndex index(pts);
  std::vector<char> seen(pts.size(), 0);
  std::vector<int> queue;
  for (std::size_t s = 0; s < pts.size(); ++s) {
    if (seen[s])
      continue;
    queue.assign(1, static_cast<int>(s));
    seen[s] = 1;
    for (std::size_t head = 0; head < queue.size(); ++head) {
      for (const int j : index.within(pts[queue[head]], tolerance)) {
        if (!seen[j]) {
          seen[j] = 1;
          queue.push_back(j);
        }
      }
    }
    if (static_cast<int>(queue.size()) >= min_size) {
      std::sort(queue.begin(), queue.end());
      clusters.push_back(queue);
    } else if (small) {
      small->insert(small->end(), queue.begin(), queue.end());
    }
  }
  std::stable_sort(
      clusters.begin(), clusters.end(),
      [](const std::vector<int>& a, const std::vector<int>& b) { return a.size() > b.size(); });
  return clusters;
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
