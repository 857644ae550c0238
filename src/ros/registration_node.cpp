#include "dormant_tree_modeling/ros/registration_node.h"

#include <dormant_tree_modeling/AcquisitionProgress.h>
#include <geometry_msgs/PoseArray.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <tf2_eigen/tf2_eigen.h>
#include <topic_tools/shape_shifter.h>

#include <cstdlib>
#include <iomanip>
#include <sstream>

#include "dormant_tree_modeling/acquisition/sequencer.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/registration/node_config.h"
#include "dormant_tree_modeling/registration/view_folder.h"
#include "dormant_tree_modeling/ros/conversions.h"
#include "dormant_tree_modeling/ros/node_support.h"
#include "dormant_tree_modeling/ros/tf_feed.h"

namespace dormant_tree_modeling {
namespace ros_layer {

namespace {

// How often the end of the input is looked for, s.
constexpr double END_OF_INPUT_CHECK_S = 1.0;

/// The registration settings and the silhouette growth of the files the node's parameters name.
registration::RegistrationConfig loadConfig(const registration::RegistrationNodeConfig& node) {
  registration::RegistrationConfig config;
  if (node.config_file.empty()) {
    ROS_WARN(
        "~config_file not set: using the built-in defaults (config/registration.yaml holds "
        "them too)");
  } else {
    config = registration::loadRegistrationConfig(node.config_file);
  }
  const bool applied = !node.calibration_file.empty() &&
                       registration::applySensorCalibration(
                           modeling::loadSensorCalibration(node.calibration_file), config);
  if (!applied) {
    ROS_WARN(
        "registration: no silhouette growth in ~calibration_file ('%s'): branch axes assume "
        "an ideal beam (calibrate the rig's views with calibrate_diameters)",
        node.calibration_file.c_str());
  }
  return config;
}

registration::RegistrationNodeConfig readNodeConfig(const ros::NodeHandle& pnh) {
  auto node = readParameters(pnh, registration::registrationNodeConfigTable());
  node.validate();
  return node;
}

std::string defaultOutputDir() {
  if (const char* ros_home = std::getenv("ROS_HOME"))
    return std::string(ros_home) + "/registration";
  if (const char* home = std::getenv("HOME"))
    return std::string(home) + "/.ros/registration";
  return "registration";
}

}  // namespace

std::optional<PlanEnd> planEnd(const topic_tools::ShapeShifter& msg) {
  if (msg.getDataType() ==
      ros::message_traits::datatype<dormant_tree_modeling::AcquisitionProgress>()) {
    const auto p = msg.instantiate<dormant_tree_modeling::AcquisitionProgress>();
    if (!p || p->state != dormant_tree_modeling::AcquisitionProgress::FINISHED)
      return std::nullopt;
    return PlanEnd{p->done};
  }
  if (msg.getDataType() == ros::message_traits::datatype<std_msgs::String>()) {
    const auto text = msg.instantiate<std_msgs::String>();
    if (!text || text->data.rfind("finished", 0) != 0)
      return std::nullopt;
    return PlanEnd{acquisition::viewsAcquired(text->data)};
  }
  ROS_WARN_ONCE("registration: progress of type %s ignored (expected %s)",
                msg.getDataType().c_str(),
                ros::message_traits::datatype<dormant_tree_modeling::AcquisitionProgress>());
  return std::nullopt;
}

RegistrationNode::RegistrationNode(ros::NodeHandle& nh, ros::NodeHandle& pnh)
    : RegistrationNode(nh, pnh, readNodeConfig(pnh)) {}

RegistrationNode::RegistrationNode(ros::NodeHandle& nh, ros::NodeHandle& pnh,
                                   const registration::RegistrationNodeConfig& node)
    : config_(loadConfig(node)), nh_(nh) {
  orchard_frame_ = node.orchard_frame;
  tree_frame_ = node.tree_frame;
  laser_frame_ = node.laser_frame;
  output_dir_ = node.output_dir.empty() ? defaultOutputDir() : node.output_dir;
  expected_views_ = node.expected_views;
  hint_timeout_ = node.hint_timeout_s;
  finished_wait_ = node.finished_wait_s;
  end_of_input_timeout_ = node.end_of_input_timeout_s;
  const std::string& input_topic = node.input_watch_topic;

  cloud_pub_ = pnh.advertise<sensor_msgs::PointCloud2>("tree_cloud", 1, true);
  poses_pub_ = pnh.advertise<geometry_msgs::PoseArray>("view_poses", 1, true);
  report_pub_ = pnh.advertise<std_msgs::String>("report", 1, true);
  view_sub_ = nh.subscribe("view_cloud", 50, &RegistrationNode::viewCallback, this);
  const std::string& progress = node.plan_progress_topic;
  if (!progress.empty())
    progress_sub_ = nh.subscribe<topic_tools::ShapeShifter>(
        progress, 10, &RegistrationNode::progressCallback, this);
  register_srv_ = pnh.advertiseService("register", &RegistrationNode::registerService, this);
  reset_srv_ = pnh.advertiseService("reset", &RegistrationNode::resetService, this);

  diagnostics_.add("registration", this, &RegistrationNode::diagnose);
  diagnostics_.start(nh, "none");
  if (end_of_input_timeout_ > 0 && !input_topic.empty()) {
    last_input_ = ros::WallTime::now();
    input_sub_ = nh.subscribe<topic_tools::ShapeShifter>(
        input_topic, 10, [this](const topic_tools::ShapeShifter::ConstPtr&) {
          std::lock_guard<std::mutex> lock(mutex_);
          last_input_ = ros::WallTime::now();
        });
    input_timer_ = nh.createWallTimer(ros::WallDuration(END_OF_INPUT_CHECK_S),
                                      [this](const ros::WallTimerEvent&) { checkEndOfInput(); });
  }
  ROS_INFO("registration: collecting views on %s; registers on ~register%s%s",
           view_sub_.getTopic().c_str(),
           expected_views_ > 0 ? (" or after " + std::to_string(expected_views_) + " views").c_str()
                               : "",
           progress.empty() ? "" : (" or when " + progress + " reports finished").c_str());
}

RegistrationNode::~RegistrationNode() {
  if (worker_.joinable())
    worker_.join();
}

void RegistrationNode::viewCallback(const sensor_msgs::PointCloud2ConstPtr& msg) {
  registration::ViewInput v;
  std::size_t dropped = 0;
  try {
    const CloudPtr cloud = fromMsg(*msg, &dropped);
    v.points.reserve(cloud->size());
    for (const auto& p : *cloud)
      v.points.emplace_back(p.x, p.y, p.z);
  } catch (const Error& e) {
    ROS_ERROR("registration: view (stamp %.3f) not used: %s", msg->header.stamp.toSec(), e.what());
    return;
  }
  // The laser's place in the view's frame (for the side a surface was seen from), and the
  // platform's hinted place in the orchard.
  v.sensor = Eigen::Vector3d::Zero();  // the frame's origin: close enough to tell the side
  if (frameKnown(tf_buffer_, laser_frame_)) {
    try {
      v.sensor = tf2::transformToEigen(lookupWithin(tf_buffer_, msg->header.frame_id, laser_frame_,
                                                    msg->header.stamp, hint_timeout_))
                     .translation();
    } catch (const tf2::TransformException& e) {
      ROS_DEBUG_THROTTLE(10.0, "registration: laser position unknown, frame origin used: %s",
                         e.what());
    }
  }
  std::optional<Eigen::Isometry3d> hint;
  try {
    hint = tf2::transformToEigen(lookupWithin(tf_buffer_, orchard_frame_, msg->header.frame_id,
                                              msg->header.stamp, hint_timeout_));
  } catch (const tf2::TransformException& e) {
    // No hint: the view starts a station of its own (said in the log line below).
    ROS_DEBUG_THROTTLE(10.0, "registration: no platform hint: %s", e.what());
  }
  bool start = false;
  using End = registration::RegistrationInput::End;
  End ended_by = End::REQUEST;
  std::optional<int> planned;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    v.station = stations_.next(hint);
    v.station_hint = hint;
    v.name = "view_" + std::to_string(views_.size());
    views_.push_back(std::move(v));
    last_stamp_ = msg->header.stamp;
    ROS_INFO("registration: %s (%zu points%s), station %d%s", views_.back().name.c_str(),
             views_.back().points.size(),
             dropped ? (", " + std::to_string(dropped) + " non-finite dropped").c_str() : "",
             views_.back().station, hint ? "" : " (no platform hint)");
    const int have = static_cast<int>(views_.size());
    if (awaited_views_ && have >= *awaited_views_) {
      start = true;
      ended_by = End::PLAN_FINISHED;
      planned = awaited_views_;
    } else if (expected_views_ > 0 && have >= expected_views_) {
      start = true;
      ended_by = End::EXPECTED_VIEWS;
      planned = expected_views_;
    }
  }
  if (start) {
    std::string why;
    if (!startRegistration(why, ended_by, planned))
      ROS_WARN("registration: %s", why.c_str());
  }
}

void RegistrationNode::progressCallback(const topic_tools::ShapeShifter::ConstPtr& msg) {
  std::optional<PlanEnd> end;
  try {
    end = planEnd(*msg);
  } catch (const ros::Exception& e) {
    ROS_WARN_THROTTLE(10.0, "registration: progress message not read: %s", e.what());
  }
  if (!end)
    return;
  const std::optional<int> named = end->views;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    const int have = static_cast<int>(views_.size());
    if (named && have < *named && finished_wait_ > 0 && !busy_) {
      // A replayed plan ends while its last sweeps are still being assembled.
      awaited_views_ = *named;
      ROS_INFO(
          "registration: the plan finished with %d views, %d here; waiting up to %.1f s for "
          "the rest",
          *named, have, finished_wait_);
      finished_timer_ = nh_.createWallTimer(
          ros::WallDuration(finished_wait_),
          [this](const ros::WallTimerEvent&) { finishedWaitExpired(); }, true);
      return;
    }
  }
  std::string why;
  if (!startRegistration(why, registration::RegistrationInput::End::PLAN_FINISHED, named))
    ROS_WARN("registration: the plan finished, but %s", why.c_str());
}

void RegistrationNode::finishedWaitExpired() {
  std::optional<int> planned;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (!awaited_views_)
      return;  // they arrived in time
    planned = awaited_views_;
    ROS_WARN("registration: the plan finished with %d views, only %zu arrived within %.1f s",
             *awaited_views_, views_.size(), finished_wait_);
  }
  std::string why;
  if (!startRegistration(why, registration::RegistrationInput::End::PLAN_FINISHED, planned))
    ROS_WARN("registration: the plan finished, but %s", why.c_str());
}

// A replay whose bag ended early, was cut off, or lacks the end-of-plan record goes quiet
// without a "finished": the views that arrived are registered rather than waited on. Quiet
// means no message on the watched topic (the stage's joint states, present all through an
// acquisition), so a long pause between two views is not taken for the end.
void RegistrationNode::checkEndOfInput() {
  double quiet = 0.0;
  std::size_t views = 0;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    quiet = (ros::WallTime::now() - last_input_).toSec();
    if (quiet < end_of_input_timeout_ || busy_ || views_.empty())
      return;
    views = views_.size();
  }
  ROS_WARN(
      "registration: the input went quiet (%s silent for %.0f s) before the plan reported "
      "finished: registering the %zu views that arrived",
      input_sub_.getTopic().c_str(), quiet, views);
  std::string why;
  if (!startRegistration(why, registration::RegistrationInput::End::INPUT_QUIET))
    ROS_WARN("registration: %s", why.c_str());
}

bool RegistrationNode::registerService(std_srvs::Trigger::Request&,
                                       std_srvs::Trigger::Response& res) {
  std::string why;
  res.success = startRegistration(why, registration::RegistrationInput::End::REQUEST);
  res.message = why;
  return true;
}

bool RegistrationNode::resetService(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  std::lock_guard<std::mutex> lock(mutex_);
  res.message = "dropped " + std::to_string(views_.size()) + " views";
  views_.clear();
  stations_.restart();
  awaited_views_.reset();
  res.success = true;
  return true;
}

bool RegistrationNode::startRegistration(std::string& why,
                                         registration::RegistrationInput::End ended_by,
                                         std::optional<int> planned) {
  registration::RegistrationInput input;
  input.ended_by = ended_by;
  input.reported_views = planned;
  std::vector<registration::ViewInput> views;
  ros::Time stamp;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    if (busy_) {
      why = "a registration is already running";
      return false;
    }
    if (views_.empty()) {
      why = "no views collected yet on " + view_sub_.getTopic();
      return false;
    }
    // The views go to the worker; new ones start the next tree.
    views.swap(views_);
    stations_.restart();
    awaited_views_.reset();
    stamp = last_stamp_;
    busy_ = true;
  }
  if (worker_.joinable())
    worker_.join();
  why = "registering " + std::to_string(views.size()) + " views";
  input.views_received = static_cast<int>(views.size());
  worker_ = std::thread(&RegistrationNode::run, this, std::move(views), stamp, std::move(input));
  return true;
}

void RegistrationNode::run(std::vector<registration::ViewInput> views, ros::Time stamp,
                           registration::RegistrationInput input) {
  std::string outcome;
  bool ok = false;
  try {
    const registration::RegistrationResult result = registration::registerViews(views, config_);
    int registered_views = 0;
    for (const auto& v : result.views) {
      registered_views += v.registered;
      if (!v.registered)
        ROS_WARN("registration: %s left out: %s", v.name.c_str(), v.reason.c_str());
    }
    const Cloud registered = registration::registeredCloud(views, result);
    publish(registered, views, result, stamp);
    std::ostringstream s;
    s << std::fixed << std::setprecision(1) << registered_views << " of " << views.size()
      << " views registered in " << result.seconds << " s";
    try {
      std::ostringstream dir;
      dir << output_dir_ << "/" << std::fixed << std::setprecision(0) << stamp.toSec();
      registration::writeRegistration(dir.str(), registered, result, std::nullopt, input);
      s << "; " << registered.size() << " points written to " << dir.str();
    } catch (const Error& e) {
      s << "; NOT written: " << e.what();
      ROS_ERROR("registration: %s", e.what());
    }
    outcome = s.str();
    ok = registered_views == static_cast<int>(views.size());
    ROS_INFO("registration: %s", outcome.c_str());
  } catch (const std::exception& e) {
    outcome = std::string("failed: ") + e.what();
    ROS_ERROR("registration: %s", outcome.c_str());
  }
  std::lock_guard<std::mutex> lock(mutex_);
  last_outcome_ = outcome;
  last_ok_ = ok;
  busy_ = false;
}

void RegistrationNode::publish(const Cloud& registered,
                               const std::vector<registration::ViewInput>& views,
                               const registration::RegistrationResult& result,
                               const ros::Time& stamp) {
  geometry_msgs::PoseArray poses;
  poses.header.frame_id = tree_frame_;
  poses.header.stamp = stamp;
  std::vector<geometry_msgs::TransformStamped> tfs;
  // The tree frame is the first registered view's platform frame; its hint places it in the
  // orchard (identity without one, so rviz can still show it).
  Eigen::Isometry3d tree_in_orchard = Eigen::Isometry3d::Identity();
  for (std::size_t i = 0; i < views.size(); ++i) {
    if (result.views[i].registered && views[i].station_hint) {
      tree_in_orchard = *views[i].station_hint * result.views[i].pose.inverse();
      break;
    }
  }
  geometry_msgs::TransformStamped root = tf2::eigenToTransform(tree_in_orchard);
  root.header.frame_id = orchard_frame_;
  root.header.stamp = stamp;
  root.child_frame_id = tree_frame_;
  tfs.push_back(root);
  for (std::size_t i = 0; i < views.size(); ++i) {
    poses.poses.push_back(tf2::toMsg(result.views[i].pose));
    if (!result.views[i].registered)
      continue;
    geometry_msgs::TransformStamped t = tf2::eigenToTransform(result.views[i].pose);
    t.header.frame_id = tree_frame_;
    t.header.stamp = stamp;
    t.child_frame_id = views[i].name;
    tfs.push_back(t);
  }
  static_tf_.sendTransform(tfs);
  poses_pub_.publish(poses);
  std_msgs::String report;
  report.data = registration::registrationReport(result, std::nullopt);
  report_pub_.publish(report);
  cloud_pub_.publish(toMsg(registered, tree_frame_, stamp));
}

void RegistrationNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  using diagnostic_msgs::DiagnosticStatus;
  std::lock_guard<std::mutex> lock(mutex_);
  status.add("views collected", views_.size());
  status.add("stations collected",
             views_.empty() ? 0 : views_.back().station - views_.front().station + 1);
  status.add("last registration", last_outcome_);
  if (busy_)
    status.summary(DiagnosticStatus::OK, "registering");
  else if (!last_ok_)
    status.summary(DiagnosticStatus::WARN, "last registration: " + last_outcome_);
  else
    status.summary(DiagnosticStatus::OK,
                   std::to_string(views_.size()) + " views collected; " + last_outcome_);
}

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
