#include "dormant_tree_modeling/ros/tf_feed.h"

#include <yaml-cpp/yaml.h>

#include <ros/rate.h>

namespace dormant_tree_modeling {
namespace ros_layer {

TfFeed::TfFeed(tf2_ros::Buffer& buffer, int queue_size) : buffer_(buffer) {
  nh_.setCallbackQueue(&queue_);
  using Event = ros::MessageEvent<const tf2_msgs::TFMessage>;
  tf_sub_ = nh_.subscribe<tf2_msgs::TFMessage>(
      "/tf", queue_size, boost::function<void(const Event&)>([this](const Event& e) {
        add(*e.getConstMessage(), e.getPublisherName(), false);
      }));
  static_sub_ = nh_.subscribe<tf2_msgs::TFMessage>(
      "/tf_static", queue_size, boost::function<void(const Event&)>([this](const Event& e) {
        add(*e.getConstMessage(), e.getPublisherName(), true);
      }));
  spinner_ = std::make_unique<ros::AsyncSpinner>(1, &queue_);
  spinner_->start();
}

TfFeed::~TfFeed() {
  spinner_->stop();
  tf_sub_.shutdown();
  static_sub_.shutdown();
}

void TfFeed::add(const tf2_msgs::TFMessage& msg, const std::string& authority, bool is_static) {
  for (const auto& t : msg.transforms) {
    try {
      buffer_.setTransform(t, authority, is_static);
    } catch (const tf2::TransformException& e) {
      ROS_ERROR_THROTTLE(10.0, "tf from %s not used: %s", authority.c_str(), e.what());
    }
  }
}

bool frameKnown(const tf2_ros::Buffer& buffer, const std::string& frame) {
  YAML::Node frames;
  try {
    frames = YAML::Load(buffer.allFramesAsYAML());
  } catch (const YAML::Exception& e) {
    ROS_WARN_THROTTLE(10.0, "tf frames not readable (%s): treating '%s' as unknown", e.what(),
                      frame.c_str());
    return false;
  }
  if (!frames.IsMap())
    return false;  // no transform yet ("[]")
  for (const auto& entry : frames) {
    if (entry.first.as<std::string>() == frame)
      return true;
    const YAML::Node parent = entry.second["parent"];
    if (parent && parent.as<std::string>() == frame)
      return true;
  }
  return false;
}

geometry_msgs::TransformStamped lookupWithin(const tf2_ros::Buffer& buffer,
                                             const std::string& target, const std::string& source,
                                             const ros::Time& stamp, double wall_timeout_s) {
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(wall_timeout_s);
  while (!buffer.canTransform(target, source, stamp) && ros::WallTime::now() < give_up)
    ros::WallDuration(0.005).sleep();
  return buffer.lookupTransform(target, source, stamp);
}

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
