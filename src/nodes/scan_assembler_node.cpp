#include <ros/ros.h>

#include "dormant_tree_modeling/ros/scan_assembler_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "scan_assembler");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  try {
    dormant_tree_modeling::ros_layer::ScanAssemblerNode node(nh, pnh);
    // A sweep blocks its service call for seconds while scans and joint states keep coming.
    ros::AsyncSpinner spinner(3);
    spinner.start();
    ros::waitForShutdown();
  } catch (const std::exception& e) {
    ROS_FATAL("scan_assembler: %s", e.what());
    return 1;
  }
  return 0;
}
