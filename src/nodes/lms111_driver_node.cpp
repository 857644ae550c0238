#include <ros/ros.h>

#include "dormant_tree_modeling/ros/lms111_driver_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "lms111_driver");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  try {
    dormant_tree_modeling::ros_layer::Lms111DriverNode node(nh, pnh);
    ros::spin();
  } catch (const std::exception& e) {
    ROS_FATAL("lms111_driver: %s", e.what());
    return 1;
  }
  return 0;
}
