#include <ros/ros.h>

#include "dormant_tree_modeling/ros/tree_modeler_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "tree_modeler");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  try {
    dormant_tree_modeling::ros_layer::TreeModelerNode node(nh, pnh);
    // Two threads: the service can model on demand while the subscriber keeps queueing.
    ros::AsyncSpinner spinner(2);
    spinner.start();
    ros::waitForShutdown();
    return node.exitStatus();
  } catch (const std::exception& e) {
    ROS_FATAL("tree_modeler: %s", e.what());
    return 1;
  }
  return 0;
}
