#include <ros/ros.h>

#include "dormant_tree_modeling/ros/stage_controller_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "stage_controller");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  try {
    dormant_tree_modeling::ros_layer::StageControllerNode node(nh, pnh);
    // Two threads: a waiting move must not hold up the home service or the diagnostics.
    ros::AsyncSpinner spinner(2);
    spinner.start();
    ros::waitForShutdown();
    // A home or move service call may be waiting on the controller: end it before the
    // spinner joins its thread.
    node.interrupt();
  } catch (const std::exception& e) {
    ROS_FATAL("stage_controller: %s", e.what());
    return 1;
  }
  return 0;
}
