#include "dormant_tree_modeling/ros/virtual_platform_node.h"

#include <std_srvs/Trigger.h>
#include <tf2_eigen/tf2_eigen.h>

#include <cmath>
#include <filesystem>
#include <nlohmann/json.hpp>
#include <sstream>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/io/pose_json.h"
#include "dormant_tree_modeling/io/tree_json.h"
#include "dormant_tree_modeling/ros/node_support.h"
#include "dormant_tree_modeling/simulation/dataset.h"
#include "dormant_tree_modeling/simulation/orchard_generator.h"
#include "dormant_tree_modeling/simulation/scene.h"

namespace dormant_tree_modeling {
namespace ros_layer {

namespace {

constexpr double DEG = M_PI / 180.0;

std::string describe(const Eigen::Isometry3d& pose) {
  const Eigen::Vector3d t = pose.translation();
  std::ostringstream s;
  s.precision(3);
  s << "x " << t.x() << " m, y " << t.y() << " m, z " << t.z() << " m, heading "
    << std::atan2(pose.linear()(1, 0), pose.linear()(0, 0)) / DEG << " deg";
  return s.str();
}

}  // namespace

VirtualPlatformNode::VirtualPlatformNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  const auto config = readParameters(pnh, simulation::virtualPlatformNodeConfigTable());
  config.validate();
  simulation::VirtualPlatformConfig o;
  o.laser.cola_a_port = config.lms_port;
  o.laser.cola_b_port = config.lms_b_port;
  o.stage_port = config.aerotech_port;
  o.scan_frequency_hz = config.scan_frequency_hz;
  o.range_noise_sigma = config.noise_mm / 1000.0;
  o.seed = static_cast<std::uint64_t>(config.seed);
  const auto& start = config.platform;
  o.platform = geometry::platformPose(start[0], start[1], start[2], start[3] * DEG);
  o.stage_faults.fault_axis = config.fault_axis;
  o.stage_faults.fault_on_move = config.fault_on_move;
  scene_frame_ = config.scene_frame;
  output_dir_ = config.output_dir;
  in_place_service_ = config.in_place_service;
  placement_error_ = config.placement_error_m;
  placement_error_yaw_deg_ = config.placement_error_yaw_deg;
  settle_s_ = config.settle_time_s;
  placement_rng_ = Rng::derive(o.seed, 17);

  const std::string& scene_file = config.scene_file;
  const std::string& preset = config.preset;
  const simulation::SceneAndTruth scene =
      simulation::sceneFromFileOrPreset(scene_file, preset, o.seed);
  if (!output_dir_.empty()) {
    std::filesystem::create_directories(output_dir_);
    simulation::saveScene(scene.scene, output_dir_ + "/scene.json");
    if (scene.truth)
      io::writeTextFile(output_dir_ + "/truth.json", io::truthToJson(*scene.truth));
  }
  platform_ = std::make_unique<simulation::VirtualPlatform>(scene.scene, o);

  pose_pub_ = pnh.advertise<geometry_msgs::PoseStamped>("platform_pose", 1, true);
  move_srv_ = pnh.advertiseService("move_platform", &VirtualPlatformNode::movePlatform, this);
  if (config.follow_goals) {
    goal_sub_ = nh.subscribe(config.goal_topic, 10, &VirtualPlatformNode::goalCallback, this);
  }
  place(o.platform, nullptr);
  diagnostics_.add("virtual platform", this, &VirtualPlatformNode::diagnose);
  diagnostics_.start(nh, "virtual platform");
  ROS_INFO(
      "virtual_platform: LMS111 on 127.0.0.1:%d (CoLa-A), %d (CoLa-B); Aerotech on "
      "127.0.0.1:%d; %s; platform at %s%s",
      platform_->laserPort(), platform_->laserColaBPort(), platform_->stagePort(),
      scene_file.empty() ? ("preset " + preset + ", seed " + std::to_string(config.seed)).c_str()
                         : scene_file.c_str(),
      describe(o.platform).c_str(),
      goal_sub_ ? ("; following goals on " + goal_sub_.getTopic()).c_str() : "");
}

VirtualPlatformNode::~VirtualPlatformNode() {
  if (platform_)
    platform_->stop();
}

void VirtualPlatformNode::place(const Eigen::Isometry3d& pose, const Eigen::Isometry3d* goal) {
  platform_->setPlatform(pose);
  geometry_msgs::PoseStamped msg;
  msg.header.stamp = ros::Time::now();
  msg.header.frame_id = scene_frame_;
  msg.pose = tf2::toMsg(pose);
  pose_pub_.publish(msg);
  std::lock_guard<std::mutex> lock(mutex_);
  ++moves_;
  placements_.push_back({pose, goal ? std::optional<Eigen::Isometry3d>(*goal) : std::nullopt});
  writeLog();
}

void VirtualPlatformNode::writeLog() {
  if (output_dir_.empty())
    return;
  nlohmann::json doc{{"frame", scene_frame_},
                     {"pose", "platform frame in the scene"},
                     {"placements", nlohmann::json::array()}};
  for (const auto& p : placements_) {
    nlohmann::json entry{{"true_pose", io::poseToJson(p.truth)}};
    if (p.goal)
      entry["goal_pose"] = io::poseToJson(*p.goal);
    doc["placements"].push_back(entry);
  }
  try {
    io::writeTextFile(output_dir_ + "/platform.json", doc.dump(2) + "\n");
  } catch (const Error& e) {
    last_problem_ = e.what();
    ROS_ERROR_THROTTLE(10.0, "virtual_platform: %s", e.what());
  }
}

bool VirtualPlatformNode::movePlatform(dormant_tree_modeling::MovePlatform::Request& req,
                                       dormant_tree_modeling::MovePlatform::Response& res) {
  try {
    const Eigen::Isometry3d pose = geometry::platformPose(req.x, req.y, req.z, req.yaw * DEG);
    place(pose, nullptr);
    res.success = true;
    res.message = "platform at " + describe(pose);
  } catch (const Error& e) {
    res.success = false;
    res.message = e.what();
  }
  return true;
}

void VirtualPlatformNode::goalCallback(const geometry_msgs::PoseStampedConstPtr& msg) {
  Eigen::Isometry3d goal;
  tf2::fromMsg(msg->pose, goal);
  Eigen::Isometry3d error = Eigen::Isometry3d::Identity();
  int index;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    index = goals_++;
  }
  // The first position is where the orchard frame is: the operator's error starts after it.
  if (index > 0)
    error =
        simulation::randomPlatformError(placement_rng_, placement_error_, placement_error_yaw_deg_);
  try {
    place(goal * error, &goal);
  } catch (const Error& e) {
    std::lock_guard<std::mutex> lock(mutex_);
    last_problem_ = std::string("cannot drive to the goal: ") + e.what();
    ROS_ERROR("virtual_platform: %s", last_problem_.c_str());
    return;
  }
  ROS_INFO("virtual_platform: drove to position %d: %s (asked for %s)", index + 1,
           describe(goal * error).c_str(), describe(goal).c_str());
  ros::WallDuration(settle_s_).sleep();
  std_srvs::Trigger in_place;
  if (!ros::service::call(in_place_service_, in_place) || !in_place.response.success) {
    std::lock_guard<std::mutex> lock(mutex_);
    last_problem_ = "could not report the platform in place on " + in_place_service_;
    ROS_ERROR("virtual_platform: %s", last_problem_.c_str());
  }
}

void VirtualPlatformNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  using diagnostic_msgs::DiagnosticStatus;
  const Eigen::Isometry3d pose = platform_->platform();
  std::lock_guard<std::mutex> lock(mutex_);
  status.add("LMS111 CoLa-A port", platform_->laserPort());
  status.add("LMS111 CoLa-B port", platform_->laserColaBPort());
  status.add("Aerotech port", platform_->stagePort());
  status.add("platform", describe(pose));
  status.add("platform moves", moves_);
  status.add("goals followed", goals_);
  if (last_problem_.empty())
    status.summary(DiagnosticStatus::OK, "serving on 127.0.0.1");
  else
    status.summary(DiagnosticStatus::WARN, last_problem_);
}

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
