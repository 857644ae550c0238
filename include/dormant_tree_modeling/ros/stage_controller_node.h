#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <tf2_ros/transform_broadcaster.h>

#include <atomic>
#include <memory>
#include <mutex>
#include <thread>

#include "dormant_tree_modeling/MoveAxis.h"
#include "dormant_tree_modeling/aerotech/stage_controller.h"
#include "dormant_tree_modeling/common/error.h"

#include "dormant_tree_modeling/ros/node_support.h"

namespace dormant_tree_modeling {
namespace ros_layer {

/// @brief ROS wrapper of the Aerotech stage (rotary stage + linear slide).
///
/// Services `~move_axis` (dormant_tree_modeling/MoveAxis) and `~home` (std_srvs/Trigger);
/// publishes `joint_states` (sensor_msgs/JointState: rad and m, stamped half-way between the
/// feedback request and its reply) at `~joint_state_rate`, the tf chain platform -> slide_base
/// (static) -> slide_carriage (prismatic) -> rotary_stage (static) -> laser (revolute θ, then
/// the LMS111's mounting: its scan plane vertical), and `/diagnostics`. Set-up (fault
/// acknowledge, enable, homing) runs in the background and is retried until it succeeds; moves
/// fail with the reason until then. The axes are aborted on shutdown. Parameters in
/// config/stage_controller.yaml.
class StageControllerNode {
 public:
  /// @throws Error INVALID_ARGUMENT for a bad parameter
  StageControllerNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  ~StageControllerNode();
  StageControllerNode(const StageControllerNode&) = delete;
  StageControllerNode& operator=(const StageControllerNode&) = delete;

  /// @brief Ends every wait on the controller at once: the set-up and feedback threads', and a
  /// move or home service call in progress (whose spinner thread is joined before the node is
  /// destroyed). Called at shutdown, before the spinner stops.
  void interrupt();

 private:
  bool moveAxis(dormant_tree_modeling::MoveAxis::Request& req,
                dormant_tree_modeling::MoveAxis::Response& res);
  bool home(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  void setUpLoop();
  void feedbackLoop();
  /// Sleeps, or returns false at once when the node stops meanwhile.
  bool sleepUnlessStopped(double seconds);
  /// Logs a connection the controller dropped (once per drop).
  void noteReconnects();
  /// Records a failed set-up or feedback round, logs the first of a streak, and returns the
  /// back-off to wait before the next one (doubling up to reconnect_max_s_).
  double failed(const Error& e, const char* what, double& backoff);
  void publishStaticFrames();
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  std::unique_ptr<aerotech::StageController> stage_;
  std::string platform_frame_, slide_base_frame_, carriage_frame_, stage_frame_, laser_frame_;
  ros::Publisher joint_pub_;
  ros::ServiceServer move_srv_, home_srv_;
  tf2_ros::TransformBroadcaster tf_;
  tf2_ros::StaticTransformBroadcaster static_tf_;
  NodeDiagnostics diagnostics_;

  std::atomic<bool> stop_{false}, ready_{false};
  std::mutex status_mutex_;
  std::string last_error_;
  aerotech::StageHealth health_;
  bool health_known_ = false;
  double feedback_rate_ = 0;  // measured, Hz
  std::thread setup_thread_, feedback_thread_;
  double reconnect_min_s_ = 0.2;  // first back-off after a failure, doubling per failure
  double reconnect_max_s_ = 5.0;
  std::atomic<std::uint64_t> reconnects_seen_{0};
};

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
