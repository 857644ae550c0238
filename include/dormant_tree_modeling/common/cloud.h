#pragma once

#include <memory>

// Forward declarations keep PCL's heavy headers out of every file that only passes clouds
// around; translation units that touch points include <pcl/point_cloud.h> and
// <pcl/point_types.h> themselves.
namespace pcl {
struct PointXYZ;
template <typename PointT>
class PointCloud;
}  // namespace pcl

namespace dormant_tree_modeling {

/// @brief The point type of every cloud in the core library (metres, frame given by context).
using Point = pcl::PointXYZ;
/// @brief The cloud type of the core library.
using Cloud = pcl::PointCloud<pcl::PointXYZ>;
using CloudPtr = std::shared_ptr<Cloud>;
using CloudConstPtr = std::shared_ptr<const Cloud>;

}  // namespace dormant_tree_modeling
