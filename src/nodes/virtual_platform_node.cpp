#include <ros/ros.h>

#include "dormant_tree_modeling/ros/virtual_platform_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "virtual_platform");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  try {
    dormant_tree_modeling::ros_layer::VirtualPlatformNode node(nh, pnh);
    // Two threads: answering the acquisition's prompt calls its service from a callback.
    ros::AsyncSpinner spinner(2);
    spinner.start();
    ros::waitForShutdown();
  } catch (const std::exception& e) {
    ROS_FATAL("virtual_platform: %s", e.what());
    return 1;
  }
  return 0;
}
