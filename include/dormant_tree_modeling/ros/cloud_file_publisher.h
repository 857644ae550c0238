#pragma once

#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>

#include <string>

namespace dormant_tree_modeling {
namespace ros_layer {

/// @brief Publishes a point cloud file (PCD, PLY or x y z text) as a latched PointCloud2.
///
/// Parameters (private): `file` (required), `frame_id` (default "orchard"),
/// `rate` (Hz; 0 publishes once, latched; default 0).
/// Topic: `cloud` (sensor_msgs/PointCloud2). Survey coordinates are recentred; the offset
/// is logged so that results can be shifted back.
class CloudFilePublisher {
 public:
  /// @param nh node handle for topics
  /// @param pnh private node handle for parameters
  /// @throws Error when the file cannot be read or parameters are invalid
  CloudFilePublisher(ros::NodeHandle& nh, ros::NodeHandle& pnh);

  /// @brief Number of points published per message.
  std::size_t size() const { return msg_.width * msg_.height; }

 private:
  void publish();

  ros::Publisher publisher_;
  ros::Timer timer_;
  sensor_msgs::PointCloud2 msg_;
};

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
