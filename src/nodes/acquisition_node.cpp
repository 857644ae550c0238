#include <ros/ros.h>

#include "dormant_tree_modeling/ros/acquisition_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "acquisition");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  try {
    dormant_tree_modeling::ros_layer::AcquisitionNode node(nh, pnh);
    // Recording callbacks keep running while the operator is being waited for.
    ros::AsyncSpinner spinner(3);
    spinner.start();
    ros::waitForShutdown();
  } catch (const std::exception& e) {
    ROS_FATAL("acquisition: %s", e.what());
    return 1;
  }
  return 0;
}
