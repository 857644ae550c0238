#include "dormant_tree_modeling/ros/scan_assembler_node.h"

#include <dormant_tree_modeling/MoveAxis.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <sensor_msgs/Image.h>
#include <tf2_eigen/tf2_eigen.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <sstream>

#include "dormant_tree_modeling/acquisition/node_configs.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/lms111/laser_scan.h"
#include "dormant_tree_modeling/ros/conversions.h"
#include "dormant_tree_modeling/ros/node_support.h"
#include "dormant_tree_modeling/ros/tf_feed.h"

namespace dormant_tree_modeling {
namespace ros_layer {

namespace {

constexpr double DEG = M_PI / 180.0;
constexpr int PASSIVE_QUEUE = 3000;
// Wall-clock wait for the stage's transform at a view's time.
constexpr double TF_WAIT_S = 1.0;
// Passive mode: how often the wait for a sweep's last lines checks for shutdown, and after how
// long it says it is still waiting.
constexpr double LINE_POLL_S = 0.5;
constexpr double LINE_WAIT_WARN_S = 10.0;

}  // namespace

ScanAssemblerNode::ScanAssemblerNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) : nh_(nh) {
  const auto config = readParameters(pnh, acquisition::assemblerConfigTable());
  config.validate();
  sweep_ = config.sweep;
  processing_ = config.processing;
  rotary_axis_ = config.rotary_axis;
  rotary_joint_ = config.rotary_joint;
  move_service_ = config.move_axis_service;
  platform_frame_ = config.platform_frame;
  tree_frame_ = config.tree_frame;
  stage_frame_ = config.rotary_stage_frame;
  tree_distance_ = config.tree_distance_m;
  max_missing_rows_ = config.max_missing_rows;
  recorder_ = std::make_unique<acquisition::SweepRecorder>(config.buffer_s);
  passive_ = config.passive;
  if (passive_) {
    watcher_ = std::make_unique<acquisition::SweepWatcher>(sweep_.theta_min_deg * DEG,
                                                           sweep_.theta_max_deg * DEG);
    worker_ = std::thread([this] { passiveLoop(); });
  }

  // A bag player that falls behind catches up in bursts: a replay must not drop scans or
  // positions (at 50 Hz, a minute of each).
  const int queue = passive_ ? PASSIVE_QUEUE : 200;
  scan_sub_ = nh.subscribe("scan", queue, &ScanAssemblerNode::scanCallback, this);
  joint_sub_ =
      nh.subscribe("joint_states", std::max(queue, 500), &ScanAssemblerNode::jointCallback, this);
  cloud_pub_ = nh.advertise<sensor_msgs::PointCloud2>("view_cloud", 2, true);
  image_pub_ = nh.advertise<sensor_msgs::Image>("range_image", 2, true);
  if (!passive_)
    acquire_srv_ = pnh.advertiseService("acquire_view", &ScanAssemblerNode::acquireView, this);
  diagnostics_.add("scan assembler", this, &ScanAssemblerNode::diagnose);
  diagnostics_.start(nh, "none");
  if (passive_)
    ROS_INFO("scan_assembler: passive, assembling the sweeps seen on %s",
             joint_sub_.getTopic().c_str());
}

ScanAssemblerNode::~ScanAssemblerNode() {
  {
    std::lock_guard<std::mutex> lock(state_mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (worker_.joinable())
    worker_.join();
}

void ScanAssemblerNode::scanCallback(const sensor_msgs::LaserScanConstPtr& msg) {
  acquisition::SweepLine l;
  l.stamp = msg->header.stamp.toSec();
  l.time_increment = msg->time_increment;
  l.phi0 = msg->angle_min - lms111::DEVICE_TO_ROS_ANGLE_DEG * DEG;
  l.phi_step = msg->angle_increment;
  l.ranges = msg->ranges;
  l.intensities = msg->intensities;
  recorder_->addLine(std::move(l), msg->scan_time);
  std::lock_guard<std::mutex> lock(state_mutex_);
  ++scans_;
  last_scan_wall_ = ros::WallTime::now().toSec();
}

void ScanAssemblerNode::jointCallback(const sensor_msgs::JointStateConstPtr& msg) {
  for (std::size_t i = 0; i < msg->name.size() && i < msg->position.size(); ++i) {
    if (msg->name[i] != rotary_joint_)
      continue;
    recorder_->addPosition(msg->header.stamp.toSec(), msg->position[i]);
    if (!watcher_)
      continue;
    if (const auto sweep = watcher_->add(msg->header.stamp.toSec(), msg->position[i])) {
      std::lock_guard<std::mutex> lock(state_mutex_);
      sweeps_.push_back(*sweep);
      wake_.notify_all();
    }
  }
}

void ScanAssemblerNode::passiveLoop() {
  while (true) {
    acquisition::WatchedSweep sweep;
    {
      std::unique_lock<std::mutex> lock(state_mutex_);
      wake_.wait(lock, [this] { return stop_ || !sweeps_.empty(); });
      if (stop_)
        return;
      sweep = sweeps_.front();
      sweeps_.pop_front();
    }
    const ros::WallTime started = ros::WallTime::now();
    try {
      // A line stamped after the sweep's end shows that all of its lines have arrived. In a
      // replay it comes, however long the player stalls: assembling before it would make a
      // view that differs from the live one.
      if (!awaitLineAfter(sweep.end))
        return;
      std::size_t dropped = 0, missing = 0;
      const acquisition::RangeImage image = acquisition::assembleRangeImage(
          recorder_->linesBetween(sweep.begin, sweep.end), recorder_->history(),
          sweep_.theta_min_deg * DEG, sweep_.theta_max_deg * DEG, &dropped,
          sweep_.theta_step_deg * DEG, &missing);
      if (image.rows == 0)
        throw Error(ErrorCode::EMPTY_INPUT, "no scan line of the sweep had stage positions");
      const std::string summary = publishView(image, dropped, missing, started);
      ROS_INFO("view assembled from a %s sweep: %s", sweep.upwards ? "rising" : "falling",
               summary.c_str());
      noteOutcome(true, summary);
    } catch (const Error& e) {
      ROS_ERROR("a sweep seen on %s gave no view: %s", joint_sub_.getTopic().c_str(), e.what());
      noteOutcome(false, e.what());
    }
  }
}

bool ScanAssemblerNode::awaitLineAfter(double stamp) {
  const ros::WallTime since = ros::WallTime::now();
  ros::WallTime warned = since;
  while (!recorder_->firstLineAfter(stamp, LINE_POLL_S)) {
    {
      std::lock_guard<std::mutex> lock(state_mutex_);
      if (stop_)
        return false;
    }
    if ((ros::WallTime::now() - warned).toSec() > LINE_WAIT_WARN_S) {
      warned = ros::WallTime::now();
      ROS_WARN(
          "scan_assembler: a sweep ended at %.3f; no later scan line on %s for %.0f s (is "
          "the bag still playing?)",
          stamp, scan_sub_.getTopic().c_str(), (warned - since).toSec());
    }
  }
  return true;
}

void ScanAssemblerNode::noteOutcome(bool ok, const std::string& message) {
  std::lock_guard<std::mutex> lock(state_mutex_);
  (ok ? views_ : failures_) += 1;
  last_ok_ = ok;
  last_outcome_ = message;
}

void ScanAssemblerNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  using diagnostic_msgs::DiagnosticStatus;
  std::lock_guard<std::mutex> lock(state_mutex_);
  status.add("mode", passive_ ? "passive (sweeps seen in joint_states)"
                              : (sweep_.continuous ? "continuous" : "step-and-scan"));
  status.add("scans received", scans_);
  status.add("views published", views_);
  status.add("views failed", failures_);
  status.add("last view", last_outcome_);
  const double age = ros::WallTime::now().toSec() - last_scan_wall_;
  if (!last_ok_)
    status.summary(DiagnosticStatus::ERROR, "last view failed: " + last_outcome_);
  else if (scans_ == 0 || age > 2.0)
    status.summary(DiagnosticStatus::WARN, "no scans from the laser on " + scan_sub_.getTopic());
  else
    status.summary(DiagnosticStatus::OK, std::to_string(views_) + " views");
}

double ScanAssemblerNode::lastScanPeriod() {
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(3.0);
  while (ros::WallTime::now() < give_up) {
    if (const auto period = recorder_->scanPeriod(ros::Time::now().toSec(), 1.0))
      return *period;
    ros::WallDuration(0.05).sleep();
  }
  throw Error(ErrorCode::IO_FAILURE, "no scans from the laser on " + scan_sub_.getTopic() +
                                         " (is the LMS111 driver streaming?)");
}

void ScanAssemblerNode::moveRotary(double target_deg, double velocity_deg_s) {
  dormant_tree_modeling::MoveAxis m;
  m.request.axis = rotary_axis_;
  m.request.target = target_deg;
  m.request.velocity = velocity_deg_s;
  m.request.wait = true;
  if (!ros::service::call(move_service_, m))
    throw Error(ErrorCode::IO_FAILURE, "the stage service " + move_service_ + " is not available");
  if (!m.response.success) {
    throw Error(ErrorCode::IO_FAILURE, "the rotary stage did not reach " +
                                           std::to_string(target_deg) +
                                           " deg: " + m.response.message);
  }
}

std::string ScanAssemblerNode::acquire() {
  const ros::WallTime started = ros::WallTime::now();
  acquisition::SweepIo io;
  io.now = [] { return ros::Time::now().toSec(); };
  io.move_rotary = [this](double target, double velocity) { moveRotary(target, velocity); };
  io.scan_period = [this] { return lastScanPeriod(); };
  recorder_->bind(io);
  std::size_t dropped = 0, missing = 0;
  acquisition::RangeImage image = acquisition::runSweep(io, sweep_, &dropped, &missing);
  return publishView(std::move(image), dropped, missing, started);
}

Eigen::Vector3d ScanAssemblerNode::treeHint(const ros::Time& stamp) {
  // Where the plan (the acquisition's orchard -> platform) puts the tree: its frame's origin,
  // the base of the trunk on the ground.
  if (!tree_frame_.empty() && frameKnown(tf_buffer_, tree_frame_)) {
    try {
      const auto t =
          lookupWithin(tf_buffer_, platform_frame_, tree_frame_, stamp, TF_WAIT_S).transform;
      return Eigen::Vector3d(t.translation.x, t.translation.y, t.translation.z);
    } catch (const tf2::TransformException& e) {
      ROS_WARN_THROTTLE(10.0, "scan_assembler: %s", e.what());
    }
  }
  ROS_WARN_ONCE("scan_assembler: no transform %s <- %s: the tree is assumed %.2f m straight ahead",
                platform_frame_.c_str(), tree_frame_.c_str(), tree_distance_);
  return Eigen::Vector3d(tree_distance_, 0.0, NAN);
}

std::string ScanAssemblerNode::publishView(acquisition::RangeImage image, std::size_t dropped,
                                           std::size_t missing, const ros::WallTime& started) {
  // A laser that dropped out mid-sweep leaves empty rows: fail the view so it is retried.
  if (missing > max_missing_rows_ * image.rows) {
    throw Error(ErrorCode::IO_FAILURE, std::to_string(missing) + " of " +
                                           std::to_string(image.rows) +
                                           " scan lines missing (did the laser drop out?)");
  }
  const std::optional<double> middle = image.middleStamp();
  if (!middle)
    throw Error(ErrorCode::EMPTY_INPUT, "no row of the range image has a scan line");
  const auto stamp = ros::Time(*middle);
  Eigen::Isometry3d stage_in_platform;
  try {
    stage_in_platform = tf2::transformToEigen(
        lookupWithin(tf_buffer_, platform_frame_, stage_frame_, stamp, TF_WAIT_S));
  } catch (const tf2::TransformException& e) {
    throw Error(ErrorCode::IO_FAILURE, std::string("no transform ") + platform_frame_ + " <- " +
                                           stage_frame_ + ": " + e.what());
  }
  sensor_msgs::Image img;
  img.header.stamp = stamp;
  img.header.frame_id = stage_frame_;
  img.height = image.rows;
  img.width = image.cols;
  img.encoding = "32FC1";
  img.step = image.cols * sizeof(float);
  img.data.resize(image.range.size() * sizeof(float));
  std::memcpy(img.data.data(), image.range.data(), img.data.size());
  image_pub_.publish(img);

  const Eigen::Vector3d tree = treeHint(stamp);
  const acquisition::ProcessedView view = acquisition::processView(
      image, stage_in_platform, tree.head<2>(), processing_,
      std::isfinite(tree.z()) ? std::optional<double>(tree.z()) : std::nullopt);
  cloud_pub_.publish(toMsg(*view.cloud, platform_frame_, stamp));
  std::ostringstream m;
  m << image.rows << " x " << image.cols << " range image (" << missing << " rows without a line, "
    << dropped << " lines without stage positions), " << view.floating_removed
    << " floating pixels removed, " << view.cloud->size() << " points in the view in "
    << (ros::WallTime::now() - started).toSec() << " s";
  return m.str();
}

bool ScanAssemblerNode::acquireView(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  std::lock_guard<std::mutex> one(acquire_mutex_);
  try {
    res.message = acquire();
    res.success = true;
    ROS_INFO("view acquired: %s", res.message.c_str());
  } catch (const Error& e) {
    res.success = false;
    res.message = e.what();
    ROS_ERROR("acquire_view failed: %s", e.what());
  }
  noteOutcome(res.success, res.message);
  return true;
}

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
