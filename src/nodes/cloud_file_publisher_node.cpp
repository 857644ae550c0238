#include <ros/ros.h>

#include "dormant_tree_modeling/ros/cloud_file_publisher.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "cloud_file_publisher");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  try {
    dormant_tree_modeling::ros_layer::CloudFilePublisher node(nh, pnh);
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("cloud_file_publisher: %s", e.what());
    return 1;
  }
  return 0;
}
