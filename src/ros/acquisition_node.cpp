#include "dormant_tree_modeling/ros/acquisition_node.h"

#include <dormant_tree_modeling/MoveAxis.h>
#include <geometry_msgs/PoseStamped.h>
#include <geometry_msgs/TransformStamped.h>
#include <std_msgs/String.h>
#include <tf2_eigen/tf2_eigen.h>

#include <boost/bind/bind.hpp>
#include <cmath>
#include <filesystem>
#include <fstream>
#include <sstream>

#include "dormant_tree_modeling/acquisition/node_configs.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/ros/node_support.h"

namespace dormant_tree_modeling {
namespace ros_layer {

namespace {

// Rate of the platform pose on /tf: a lookup at a view's time waits at most one period.
constexpr double PLATFORM_TF_HZ = 20.0;
using Progress = dormant_tree_modeling::AcquisitionProgress;

}  // namespace

AcquisitionNode::AcquisitionNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) : nh_(nh) {
  const auto config = readParameters(pnh, acquisition::acquisitionNodeConfigTable());
  config.validate();
  if (!config.plan_file.empty())
    plan_ = acquisition::loadViewPlan(config.plan_file);
  plan_.validate();
  output_dir_ = config.output_dir;
  tree_name_ = config.tree_name;
  move_service_ = config.move_axis_service;
  acquire_service_ = config.acquire_view_service;
  slide_axis_ = config.slide_axis;
  orchard_frame_ = config.orchard_frame;
  platform_frame_ = config.platform_frame;
  slide_centre_ = config.slide_centre_m;
  slide_velocity_ = config.slide_velocity_mps;
  max_retries_ = config.max_retries;
  drain_s_ = config.drain_s;
  service_wait_s_ = config.service_wait_s;
  topics_ = config.record_topics;
  prompt_pub_ = pnh.advertise<std_msgs::String>("prompt", 1, true);
  progress_pub_ = pnh.advertise<dormant_tree_modeling::AcquisitionProgress>("progress", 1, true);
  goal_pub_ = pnh.advertise<geometry_msgs::PoseStamped>("platform_goal", 1, true);
  start_srv_ = pnh.advertiseService("start", &AcquisitionNode::start, this);
  cancel_srv_ = pnh.advertiseService("cancel", &AcquisitionNode::cancel, this);
  in_place_srv_ =
      pnh.advertiseService("platform_in_place", &AcquisitionNode::platformInPlace, this);
  for (const auto& topic : topics_) {
    recorders_.push_back(nh.subscribe<topic_tools::ShapeShifter>(
        topic, 1000, boost::bind(&AcquisitionNode::record, this, topic, boost::placeholders::_1)));
  }
  total_ = static_cast<int>(acquisition::makeViewPlan(plan_).size());
  {
    acquisition::SequencerProgress idle;
    idle.total = total_;
    publishProgress(Progress::IDLE, idle,
                    "idle: " + std::to_string(total_) + " views planned; call ~start");
  }
  diagnostics_.add("acquisition", this, &AcquisitionNode::diagnose);
  diagnostics_.start(nh, "none");
  platform_tf_timer_ = nh.createTimer(ros::Duration(1.0 / PLATFORM_TF_HZ),
                                      [this](const ros::TimerEvent&) { republishPlatform(); });
  if (config.autostart) {
    running_ = true;
    worker_ = std::thread([this] { run(); });
  }
}

void AcquisitionNode::republishPlatform() {
  std::lock_guard<std::mutex> lock(mutex_);
  if (!platform_tf_)
    return;
  const ros::Time now = ros::Time::now();
  if (now <= platform_tf_->header.stamp)
    return;  // tf refuses a repeated stamp
  platform_tf_->header.stamp = now;
  platform_tf_pub_.sendTransform(*platform_tf_);
}

AcquisitionNode::~AcquisitionNode() {
  cancel_ = true;
  wake_.notify_all();
  if (worker_.joinable())
    worker_.join();
}

void AcquisitionNode::publish(ros::Publisher& pub, const std::string& text) {
  std_msgs::String m;
  m.data = text;
  pub.publish(m);
}

dormant_tree_modeling::AcquisitionProgress AcquisitionNode::progressMessage(
    std::uint8_t state, const acquisition::SequencerProgress& p, const std::string& text) {
  dormant_tree_modeling::AcquisitionProgress m;
  m.state = state;
  m.view = p.view;
  m.done = p.done;
  m.failed = p.failed;
  m.planned = p.total;
  m.elapsed_s = p.elapsed_s;
  m.remaining_s = p.remaining_s;
  m.text = text;
  return m;
}

void AcquisitionNode::publishProgress(std::uint8_t state, const acquisition::SequencerProgress& p,
                                      const std::string& text) {
  progress_pub_.publish(progressMessage(state, p, text));
}

void AcquisitionNode::record(const std::string& topic,
                             const topic_tools::ShapeShifter::ConstPtr& msg) {
  std::lock_guard<std::mutex> lock(bag_mutex_);
  if (!recording_)
    return;
  try {
    bag_.write(topic, ros::Time::now(), msg);
  } catch (const rosbag::BagException& e) {
    ROS_ERROR_THROTTLE(5.0, "recording %s failed: %s", topic.c_str(), e.what());
  }
}

bool AcquisitionNode::start(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  if (running_.exchange(true)) {
    res.success = false;
    res.message = "a run is already going on";
    return true;
  }
  if (worker_.joinable())
    worker_.join();
  cancel_ = false;
  worker_ = std::thread([this] { run(); });
  res.success = true;
  res.message = "started";
  return true;
}

bool AcquisitionNode::cancel(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  cancel_ = true;
  wake_.notify_all();
  res.success = running_;
  res.message = running_ ? "cancelling after the current view" : "no run to cancel";
  return true;
}

bool AcquisitionNode::platformInPlace(std_srvs::Trigger::Request&,
                                      std_srvs::Trigger::Response& res) {
  std::lock_guard<std::mutex> lock(mutex_);
  in_place_ = true;
  wake_.notify_all();
  res.success = true;
  res.message = "thanks";
  return true;
}

bool AcquisitionNode::askForPlatform(const acquisition::PlannedView& view) {
  const Eigen::Vector3d t = view.platform.translation();
  const double yaw = std::atan2(view.platform.linear()(1, 0), view.platform.linear()(0, 0));
  std::ostringstream m;
  m.precision(3);
  m << "Move the platform to position " << view.platform_index + 1 << " (" << view.side << "): x "
    << t.x() << " m, y " << t.y() << " m, laser height " << t.z() << " m, heading "
    << yaw * 180.0 / M_PI << " deg in the tree frame; then call ~platform_in_place";
  {
    std::lock_guard<std::mutex> lock(mutex_);
    in_place_ = false;
    state_ = "waiting for the platform at position " + std::to_string(view.platform_index + 1);
  }
  geometry_msgs::PoseStamped goal;
  goal.header.stamp = ros::Time::now();
  goal.header.frame_id = orchard_frame_;
  goal.pose = tf2::toMsg(view.platform);
  goal_pub_.publish(goal);
  publish(prompt_pub_, m.str());
  ROS_INFO("%s", m.str().c_str());
  std::unique_lock<std::mutex> lock(mutex_);
  wake_.wait(lock, [&] { return in_place_ || cancel_ || !ros::ok(); });
  if (!in_place_)
    return false;
  state_ = "scanning";  // still under the lock of the wait
  // The plan's pose is the registration's first guess for the views from here.
  geometry_msgs::TransformStamped tf = tf2::eigenToTransform(view.platform);
  tf.header.stamp = ros::Time::now();
  tf.header.frame_id = orchard_frame_;
  tf.child_frame_id = platform_frame_;
  platform_tf_ = tf;
  platform_tf_pub_.sendTransform(tf);
  publish(prompt_pub_, "platform at position " + std::to_string(view.platform_index + 1));
  return true;
}

void AcquisitionNode::run() {
  const auto plan = acquisition::makeViewPlan(plan_);
  std::filesystem::create_directories(output_dir_);
  const std::string bag_path = output_dir_ + "/" + tree_name_ + ".bag";
  if (!openBag(bag_path, static_cast<int>(plan.size())))
    return;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    state_ = "running";
    done_ = failed_ = 0;
    total_ = static_cast<int>(plan.size());
    last_progress_ = acquisition::SequencerProgress{};
    last_problem_.clear();
  }
  std::vector<acquisition::ViewOutcome> outcomes;
  try {
    outcomes = acquisition::runPlan(plan, sequencerActions(), max_retries_);
  } catch (const Error& e) {
    ROS_ERROR("acquisition stopped: %s", e.what());
    std::lock_guard<std::mutex> lock(mutex_);
    last_problem_ = std::string("stopped: ") + e.what();
  }
  finishRun(outcomes, static_cast<int>(plan.size()), bag_path);
}

bool AcquisitionNode::openBag(const std::string& bag_path, int planned) {
  try {
    std::lock_guard<std::mutex> lock(bag_mutex_);
    bag_.open(bag_path, rosbag::bagmode::Write);
    recording_ = true;
    return true;
  } catch (const rosbag::BagException& e) {
    acquisition::SequencerProgress none;
    none.total = planned;
    publishProgress(Progress::FAILED, none,
                    std::string("cannot record to ") + bag_path + ": " + e.what());
    ROS_ERROR("cannot record to %s: %s", bag_path.c_str(), e.what());
    std::lock_guard<std::mutex> lock(mutex_);
    last_problem_ = std::string("cannot record to ") + bag_path + ": " + e.what();
    state_ = "idle";
    running_ = false;
    return false;
  }
}

void AcquisitionNode::moveSlide(double slide) {
  dormant_tree_modeling::MoveAxis m;
  m.request.axis = slide_axis_;
  m.request.target = slide_centre_ + slide;
  m.request.velocity = slide_velocity_;
  m.request.wait = true;
  // At start-up the stage may still be connecting or homing: wait for it a while.
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(service_wait_s_);
  while (true) {
    if (!ros::service::waitForService(move_service_, ros::Duration(service_wait_s_)) ||
        !ros::service::call(move_service_, m))
      throw Error(ErrorCode::IO_FAILURE,
                  "the stage service " + move_service_ + " is not available");
    if (m.response.success)
      return;
    if (m.response.status != dormant_tree_modeling::MoveAxis::Response::NOT_READY ||
        ros::WallTime::now() > give_up || cancel_)
      throw Error(ErrorCode::IO_FAILURE, "slide move failed: " + m.response.message);
    ros::WallDuration(0.5).sleep();
  }
}

std::string AcquisitionNode::acquireView() {
  std_srvs::Trigger t;
  if (!ros::service::waitForService(acquire_service_, ros::Duration(service_wait_s_)) ||
      !ros::service::call(acquire_service_, t))
    throw Error(ErrorCode::IO_FAILURE,
                "the assembler service " + acquire_service_ + " is not available");
  if (!t.response.success)
    throw Error(ErrorCode::IO_FAILURE, t.response.message);
  return t.response.message;
}

acquisition::SequencerActions AcquisitionNode::sequencerActions() {
  acquisition::SequencerActions a;
  a.move_platform = [this](const acquisition::PlannedView& v) { return askForPlatform(v); };
  a.move_slide = [this](double slide) { moveSlide(slide); };
  a.acquire_view = [this](const acquisition::PlannedView&) { return acquireView(); };
  a.progress = [this](const acquisition::SequencerProgress& p) {
    const std::string line = acquisition::progressLine(p);
    publishProgress(Progress::RUNNING, p, line);
    last_progress_ = p;
    ROS_INFO("%s", line.c_str());
    std::lock_guard<std::mutex> lock(mutex_);
    done_ = p.done;
    failed_ = p.failed;
  };
  a.cancelled = [this] { return cancel_.load() || !ros::ok(); };
  return a;
}

void AcquisitionNode::finishRun(const std::vector<acquisition::ViewOutcome>& outcomes, int planned,
                                const std::string& bag_path) {
  // Messages of the last view may still be in transit (the view cloud is published just
  // before acquire_view returns): let them arrive before the bag closes.
  ros::WallDuration(drain_s_).sleep();
  const std::string report = acquisition::outcomesMarkdown(outcomes, planned);
  const std::string summary = report.substr(0, report.find('\n'));
  acquisition::SequencerProgress end = last_progress_;
  end.total = planned;
  end.done = 0;
  end.failed = 0;
  for (const auto& o : outcomes)
    (o.ok ? end.done : end.failed) += 1;
  const auto finished = progressMessage(Progress::FINISHED, end, "finished: " + summary);
  {
    std::lock_guard<std::mutex> lock(bag_mutex_);
    recording_ = false;
    // The bag ends with the plan's end, so a replay knows when the last view is in.
    try {
      bag_.write(progress_pub_.getTopic(), ros::Time::now(), finished);
    } catch (const rosbag::BagException& e) {
      ROS_ERROR("recording the end of the plan failed: %s", e.what());
    }
    bag_.close();
  }
  std::ofstream(output_dir_ + "/" + tree_name_ + "_report.md")
      << "# Acquisition of " << tree_name_ << "\n\nBag: " << bag_path << "\n\n"
      << report;
  // Only now: whoever hears "finished" may read the bag and the report at once.
  progress_pub_.publish(finished);
  ROS_INFO("acquisition finished: %s", summary.c_str());
  {
    std::lock_guard<std::mutex> lock(mutex_);
    state_ = "finished: " + summary;
  }
  running_ = false;
}

void AcquisitionNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  using diagnostic_msgs::DiagnosticStatus;
  std::lock_guard<std::mutex> lock(mutex_);
  status.add("state", state_);
  status.add("views done", done_);
  status.add("views failed", failed_);
  status.add("views planned", total_);
  status.add("bag", output_dir_ + "/" + tree_name_ + ".bag");
  if (!last_problem_.empty())
    status.summary(DiagnosticStatus::ERROR, last_problem_);
  else if (failed_ > 0)
    status.summary(DiagnosticStatus::WARN, std::to_string(failed_) + " views failed");
  else
    status.summary(DiagnosticStatus::OK, state_);
}

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
