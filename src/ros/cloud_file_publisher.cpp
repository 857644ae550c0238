#include "dormant_tree_modeling/ros/cloud_file_publisher.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/io/point_cloud_io.h"
#include "dormant_tree_modeling/ros/conversions.h"
#include "dormant_tree_modeling/ros/node_support.h"

namespace dormant_tree_modeling {
namespace ros_layer {

CloudFilePublisher::CloudFilePublisher(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  const auto config = readParameters(pnh, io::cloudPublisherConfigTable());
  config.validate();
  file_ = config.file;
  const std::string& file = file_;
  const std::string& frame_id = config.frame_id;
  const double rate = config.rate_hz;
  const auto loaded = io::readCloud(file);
  if (loaded.dropped_non_finite > 0) {
    ROS_WARN("%s: dropped %zu NaN/Inf points of %zu", file.c_str(), loaded.dropped_non_finite,
             loaded.points_in_file);
  }
  dropped_ = loaded.dropped_non_finite;
  if (!loaded.offset.isZero()) {
    offset_ = std::to_string(loaded.offset.x()) + ", " + std::to_string(loaded.offset.y()) + ", " +
              std::to_string(loaded.offset.z());
    ROS_INFO("%s: survey coordinates recentred; original = published + (%.3f, %.3f, %.3f)",
             file.c_str(), loaded.offset.x(), loaded.offset.y(), loaded.offset.z());
  }
  msg_ = toMsg(*loaded.cloud, frame_id, ros::Time::now());
  publisher_ = nh.advertise<sensor_msgs::PointCloud2>("cloud", 1, /*latch=*/true);
  ROS_INFO("publishing %zu points from %s in frame '%s'%s", loaded.cloud->size(), file.c_str(),
           frame_id.c_str(), rate > 0.0 ? "" : " (latched, once)");
  diagnostics_.add("cloud file", this, &CloudFilePublisher::diagnose);
  diagnostics_.start(nh, "none");
  publish();
  if (rate > 0.0) {
    timer_ =
        nh.createTimer(ros::Duration(1.0 / rate), [this](const ros::TimerEvent&) { publish(); });
  }
}

void CloudFilePublisher::publish() {
  msg_.header.stamp = ros::Time::now();
  publisher_.publish(msg_);
  ++published_;
}

void CloudFilePublisher::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  status.add("file", file_);
  status.add("points", size());
  status.add("NaN/Inf points dropped", dropped_);
  status.add("survey offset (m)", offset_.empty() ? std::string("none") : offset_);
  status.add("publications", published_);
  status.summary(diagnostic_msgs::DiagnosticStatus::OK,
                 "published " + std::to_string(size()) + " points");
}

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
