#include <ros/ros.h>

#include "dormant_tree_modeling/ros/registration_node.h"

int main(int argc, char** argv) {
  ros::init(argc, argv, "registration");
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  try {
    dormant_tree_modeling::ros_layer::RegistrationNode node(nh, pnh);
    // Two threads: views keep arriving while a service call waits on tf.
    ros::AsyncSpinner spinner(2);
    spinner.start();
    ros::waitForShutdown();
  } catch (const std::exception& e) {
    ROS_FATAL("registration: %s", e.what());
    return 1;
  }
  return 0;
}
