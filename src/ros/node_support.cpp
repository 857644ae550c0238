#include "dormant_tree_modeling/ros/node_support.h"

namespace dormant_tree_modeling {
namespace ros_layer {

void NodeDiagnostics::start(ros::NodeHandle& nh, const std::string& hardware_id) {
  updater_.setHardwareID(hardware_id);
  timer_ =
      nh.createTimer(ros::Duration(1.0), [this](const ros::TimerEvent&) { updater_.update(); });
}

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
