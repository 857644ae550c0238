#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>

#include <string>

#include "dormant_tree_modeling/ros/node_support.h"

namespace dormant_tree_modeling {
namespace ros_layer {

/// @brief Publishes a point cloud file (PCD, PLY or x y z text) as a latched PointCloud2.
///
/// Parameters (private): `file` (required), `frame_id` (default "orchard"),
/// `rate` (Hz; 0 publishes once, latched; default 0).
/// Topic: `cloud` (sensor_msgs/PointCloud2). Survey coordinates are recentred; the offset
/// is logged so that results can be shifted back. Diagnostics: the file, its points, the
/// offset, publications.
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
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  ros::Publisher publisher_;
  ros::Timer timer_;
  NodeDiagnostics diagnostics_;
  sensor_msgs::PointCloud2 msg_;
  std::string file_, offset_;
  std::size_t dropped_ = 0, published_ = 0;
};

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
