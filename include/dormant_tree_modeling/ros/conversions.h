#pragma once

#include <sensor_msgs/PointCloud2.h>

#include <cstddef>
#include <string>

#include "dormant_tree_modeling/common/cloud.h"

namespace dormant_tree_modeling {
namespace ros_layer {

/// @brief Core cloud -> PointCloud2 (fields x, y, z as float32).
/// @param cloud points
/// @param frame_id header frame
/// @param stamp header stamp
sensor_msgs::PointCloud2 toMsg(const Cloud& cloud, const std::string& frame_id,
                               const ros::Time& stamp);

/// @brief PointCloud2 with float32 x, y, z fields -> core cloud, dropping NaN/Inf points.
/// @param msg incoming cloud (organised or not, any extra fields)
/// @param dropped_non_finite set to the number of points dropped
/// @throws Error PARSE_ERROR when x/y/z are missing or not float32
CloudPtr fromMsg(const sensor_msgs::PointCloud2& msg, std::size_t* dropped_non_finite = nullptr);

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
