#include "dormant_tree_modeling/modeling/point_index.h"

#include <pcl/kdtree/kdtree_flann.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>

namespace dormant_tree_modeling {
namespace modeling {

struct PointIndex::Impl {
  pcl::PointCloud<pcl::PointXYZ>::Ptr cloud{new pcl::PointCloud<pcl::PointXYZ>};
  pcl::KdTreeFLANN<pcl::PointXYZ> tree{false};  // unsorted radius results: faster
};

PointIndex::PointIndex(const Points& pts) : impl_(new Impl), size_(pts.size()) {
  impl_->cloud->reserve(pts.size());
  for (const auto& p : pts) {
    impl_->cloud->push_back(pcl::PointXYZ(static_cast<float>(p.x()), static_cast<float>(p.y()),
                                          static_cast<float>(p.z())));
  }
  if (!pts.empty())
    impl_->tree.setInputCloud(impl_->cloud);
}

PointIndex::~PointIndex() = default;

std::vector<int> PointIndex::nearest(const Eigen::Vector3d& q, int k) const {
  std::vector<int> idx;
  if (size_ == 0 || k <= 0)
    return idx;
  std::vector<float> d;
  const pcl::PointXYZ p(static_cast<float>(q.x()), static_cast<float>(q.y()),
                        static_cast<float>(q.z()));
  impl_->tree.nearestKSearch(p, std::min<int>(k, static_cast<int>(size_)), idx, d);
  return idx;
}

std::vector<int> PointIndex::within(const Eigen::Vector3d& q, double radius) const {
  std::vector<int> idx;
  if (size_ == 0)
    return idx;
  std::vector<float> d;
  const pcl::PointXYZ p(static_cast<float>(q.x()), static_cast<float>(q.y()),
                        static_cast<float>(q.z()));
  impl_->tree.radiusSearch(p, radius, idx, d);
  return idx;
}

int PointIndex::countWithin(const Eigen::Vector3d& q, double radius, int limit) const {
  if (size_ == 0)
    return 0;
  std::vector<int> idx;
  std::vector<float> d;
  const pcl::PointXYZ p(static_cast<float>(q.x()), static_cast<float>(q.y()),
                        static_cast<float>(q.z()));
  return impl_->tree.radiusSearch(p, radius, idx, d, static_cast<unsigned int>(limit));
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
