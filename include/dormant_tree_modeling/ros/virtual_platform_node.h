#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <dormant_tree_modeling/MovePlatform.h>
#include <geometry_msgs/PoseStamped.h>
#include <ros/ros.h>

#include <memory>
#include <mutex>
#include <optional>
#include <string>
#include <vector>

#include "dormant_tree_modeling/common/random.h"
#include "dormant_tree_modeling/simulation/virtual_platform.h"

#include "dormant_tree_modeling/ros/node_support.h"

namespace dormant_tree_modeling {
namespace ros_layer {

/// @brief The scanning platform without hardware (architecture.md `virtual_platform`).
///
/// Serves an LMS111 (CoLa-A `~lms_port`, CoLa-B `~lms_b_port`) and an Aerotech Ensemble
/// (`~aerotech_port`) on 127.0.0.1 from one synthetic orchard (`~scene_file`, or `~preset` and
/// `~seed`), the laser scanning from the emulated stage's pose on the platform. Service
/// `~move_platform` (MovePlatform) puts the platform elsewhere; latched `~platform_pose`
/// (geometry_msgs/PoseStamped, frame `~scene_frame`) tells where it truly is.
///
/// With `~follow_goals`, it also plays the operator: each pose the acquisition asks for on
/// `~goal_topic` is driven to, off by a seeded error of up to `~placement_error` m and
/// `~placement_error_yaw` deg (the first position is exact: it defines the orchard frame the
/// registration reports in), and answered through `~in_place_service`.
/// With `~output_dir`, writes scene.json, truth.json (the target tree) and platform.json (each
/// goal and the true pose) there, so a run can be scored against the truth.
/// Diagnostics: ports, platform pose, moves.
class VirtualPlatformNode {
 public:
  /// @throws Error for a bad parameter or a port that cannot be bound
  VirtualPlatformNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  ~VirtualPlatformNode();
  VirtualPlatformNode(const VirtualPlatformNode&) = delete;
  VirtualPlatformNode& operator=(const VirtualPlatformNode&) = delete;

 private:
  bool movePlatform(dormant_tree_modeling::MovePlatform::Request& req,
                    dormant_tree_modeling::MovePlatform::Response& res);
  void goalCallback(const geometry_msgs::PoseStampedConstPtr& msg);
  /// Moves the platform, publishes and logs its pose; throws Error on a bad pose.
  void place(const Eigen::Isometry3d& pose, const Eigen::Isometry3d* goal);
  void writeLog();  // platform.json; under mutex_
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  std::unique_ptr<simulation::VirtualPlatform> platform_;
  std::string scene_frame_, output_dir_, in_place_service_;
  double placement_error_ = 0.0, placement_error_yaw_deg_ = 0.0, settle_s_ = 0.0;
  Rng placement_rng_{0};

  ros::Publisher pose_pub_;
  ros::Subscriber goal_sub_;
  ros::ServiceServer move_srv_;
  NodeDiagnostics diagnostics_;

  std::mutex mutex_;
  int goals_ = 0, moves_ = 0;
  std::string last_problem_;
  struct Placement {
    Eigen::Isometry3d truth;
    std::optional<Eigen::Isometry3d> goal;  // when it followed the acquisition's goal
  };
  std::vector<Placement> placements_;  // platform.json
};

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
