#include "dormant_tree_modeling/ros/stage_controller_node.h"

#include <geometry_msgs/TransformStamped.h>
#include <sensor_msgs/JointState.h>

#include <cmath>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/ros/node_support.h"

namespace dormant_tree_modeling {
namespace ros_layer {

namespace {

constexpr double DEG = M_PI / 180.0;
// Shutdown: the axes' aborts get this long in all (the node stops within 2 s; a controller
// that answers at all answers an ABORT in milliseconds).
constexpr double STOP_DEADLINE_S = 0.6;
// Longest sleep between two looks at the stop flag, s.
constexpr double STOP_POLL_S = 0.05;
constexpr double HEALTH_PERIOD_S = 1.0;

geometry_msgs::TransformStamped transform(const std::string& parent, const std::string& child,
                                          const Eigen::Vector3d& t, const Eigen::Quaterniond& q,
                                          const ros::Time& stamp) {
  geometry_msgs::TransformStamped m;
  m.header.stamp = stamp;
  m.header.frame_id = parent;
  m.child_frame_id = child;
  m.transform.translation.x = t.x();
  m.transform.translation.y = t.y();
  m.transform.translation.z = t.z();
  m.transform.rotation.x = q.x();
  m.transform.rotation.y = q.y();
  m.transform.rotation.z = q.z();
  m.transform.rotation.w = q.w();
  return m;
}

/// The service's status code for a move's outcome.
std::uint8_t moveStatus(aerotech::MoveStatus status) {
  using Response = dormant_tree_modeling::MoveAxis::Response;
  switch (status) {
    case aerotech::MoveStatus::OK:
      return Response::OK;
    case aerotech::MoveStatus::NOT_READY:
      return Response::NOT_READY;
    case aerotech::MoveStatus::REFUSED:
      return Response::REFUSED;
    case aerotech::MoveStatus::FAILED:
      break;
  }
  return Response::FAILED;
}

}  // namespace

StageControllerNode::StageControllerNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  const auto config = readParameters(pnh, aerotech::stageNodeConfigTable());
  config.validate();
  stage_ = std::make_unique<aerotech::StageController>(config.stage);
  platform_frame_ = config.platform_frame;
  slide_base_frame_ = config.slide_base_frame;
  carriage_frame_ = config.slide_carriage_frame;
  stage_frame_ = config.rotary_stage_frame;
  laser_frame_ = config.laser_frame;
  reconnect_min_s_ = config.reconnect_min_s;
  reconnect_max_s_ = config.reconnect_max_s;
  joint_pub_ = nh.advertise<sensor_msgs::JointState>("joint_states", 50);
  move_srv_ = pnh.advertiseService("move_axis", &StageControllerNode::moveAxis, this);
  home_srv_ = pnh.advertiseService("home", &StageControllerNode::home, this);
  publishStaticFrames();
  const auto& c = stage_->config().controller;
  diagnostics_.add("stage", this, &StageControllerNode::diagnose);
  diagnostics_.start(nh, "Aerotech Ensemble " + c.host + ":" + std::to_string(c.port));
  setup_thread_ = std::thread([this] { setUpLoop(); });
  feedback_thread_ = std::thread([this] { feedbackLoop(); });
}

void StageControllerNode::interrupt() {
  stop_ = true;
  stage_->interrupt();  // the threads' calls on a silent controller return at once
}

StageControllerNode::~StageControllerNode() {
  interrupt();
  if (setup_thread_.joinable())
    setup_thread_.join();
  if (feedback_thread_.joinable())
    feedback_thread_.join();
  stage_->stopAll(STOP_DEADLINE_S);
}

bool StageControllerNode::sleepUnlessStopped(double seconds) {
  const ros::WallTime end = ros::WallTime::now() + ros::WallDuration(seconds);
  while (!stop_) {
    const double left = (end - ros::WallTime::now()).toSec();
    if (left <= 0)
      return true;
    ros::WallDuration(std::min(left, STOP_POLL_S)).sleep();
  }
  return false;
}

void StageControllerNode::noteReconnects() {
  const std::uint64_t now = stage_->reconnects();
  const std::uint64_t before = reconnects_seen_.exchange(now);
  if (now > before) {
    ROS_WARN(
        "stage: the connection to the controller at %s:%d dropped and was opened again "
        "(%llu times in all)",
        stage_->config().controller.host.c_str(), stage_->config().controller.port,
        static_cast<unsigned long long>(now));
  }
}

double StageControllerNode::failed(const Error& e, const char* what, double& backoff) {
  {
    std::lock_guard<std::mutex> lock(status_mutex_);
    last_error_ = e.what();
    health_known_ = false;
  }
  const double wait = backoff;
  // The first failure of a streak is logged; while it lasts, once a minute (the diagnostics
  // carry the last error meanwhile).
  if (backoff == reconnect_min_s_) {
    ROS_ERROR("stage %s failed: %s; retrying in %.1f s, doubling up to %.1f s", what, e.what(),
              wait, reconnect_max_s_);
  } else {
    ROS_ERROR_THROTTLE(60.0, "stage %s still failing: %s", what, e.what());
  }
  backoff = std::min(reconnect_max_s_, backoff * 2.0);
  return wait;
}

void StageControllerNode::setUpLoop() {
  double backoff = reconnect_min_s_;
  while (!stop_ && !ready_) {
    try {
      stage_->setUp();
      ready_ = true;
      ROS_INFO("stage ready: axes %s and %s enabled%s", stage_->config().rotary.axis.c_str(),
               stage_->config().slide.axis.c_str(),
               stage_->config().home_on_start ? " and homed" : "");
    } catch (const Error& e) {
      if (stop_)
        break;
      sleepUnlessStopped(failed(e, "set-up", backoff));
    }
  }
}

void StageControllerNode::feedbackLoop() {
  const auto& c = stage_->config();
  ros::WallRate rate(c.joint_state_rate_hz);
  ros::WallTime last_health(0.0), window_start = ros::WallTime::now();
  int samples = 0;
  double backoff = reconnect_min_s_;
  while (!stop_ && ros::ok()) {
    try {
      const ros::Time before = ros::Time::now();
      const aerotech::StageFeedback f = stage_->feedback();
      const ros::Time after = ros::Time::now();
      const ros::Time stamp = before + (after - before) * 0.5;
      sensor_msgs::JointState js;
      js.header.stamp = stamp;
      js.name = {c.rotary.joint, c.slide.joint};
      js.position = {f.rotary * DEG, f.slide};
      joint_pub_.publish(js);
      tf_.sendTransform(
          {transform(slide_base_frame_, carriage_frame_, Eigen::Vector3d(0.0, f.slide, 0.0),
                     Eigen::Quaterniond::Identity(), stamp),
           transform(
               stage_frame_, laser_frame_,
               Eigen::AngleAxisd(f.rotary * DEG, Eigen::Vector3d::UnitZ()) *
                   c.geometry.stage_to_laser,
               // The LMS111 lies on its side: its scan plane is the stage's
               // vertical plane at θ (LaserScan angle +90° points up).
               Eigen::Quaterniond(Eigen::AngleAxisd(f.rotary * DEG, Eigen::Vector3d::UnitZ()) *
                                  Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitX())),
               stamp)});
      ++samples;
      const ros::WallTime now = ros::WallTime::now();
      if ((now - last_health).toSec() > HEALTH_PERIOD_S) {
        const aerotech::StageHealth h = stage_->health();
        std::lock_guard<std::mutex> lock(status_mutex_);
        health_ = h;
        health_known_ = true;
        feedback_rate_ = samples / std::max(1e-3, (now - window_start).toSec());
        samples = 0;
        window_start = now;
        last_health = now;
      }
      backoff = reconnect_min_s_;
      noteReconnects();
    } catch (const Error& e) {
      if (stop_)
        break;
      sleepUnlessStopped(failed(e, "feedback", backoff));
      continue;
    }
    rate.sleep();
  }
}

void StageControllerNode::publishStaticFrames() {
  const auto& g = stage_->config().geometry;
  const ros::Time now = ros::Time::now();
  static_tf_.sendTransform({transform(platform_frame_, slide_base_frame_, g.platform_to_slide_base,
                                      Eigen::Quaterniond::Identity(), now),
                            transform(carriage_frame_, stage_frame_, g.carriage_to_stage,
                                      Eigen::Quaterniond::Identity(), now)});
}

bool StageControllerNode::moveAxis(dormant_tree_modeling::MoveAxis::Request& req,
                                   dormant_tree_modeling::MoveAxis::Response& res) {
  if (!ready_) {
    std::lock_guard<std::mutex> lock(status_mutex_);
    res.status = dormant_tree_modeling::MoveAxis::Response::NOT_READY;
    res.success = false;
    res.message = "stage not ready: " + (last_error_.empty() ? "setting up" : last_error_);
    return true;
  }
  aerotech::MoveRequest q;
  q.axis = req.axis;
  q.target = req.target;
  q.velocity = req.velocity;
  q.relative = req.relative;
  q.wait = req.wait;
  const aerotech::MoveResult r = stage_->move(q);
  noteReconnects();
  res.status = moveStatus(r.status);
  res.success = r.success();
  res.message = r.message;
  res.position = r.position;
  if (!r.success()) {
    std::lock_guard<std::mutex> lock(status_mutex_);
    last_error_ = r.message;
    ROS_ERROR("move_axis %s: %s", req.axis.c_str(), r.message.c_str());
  }
  return true;
}

bool StageControllerNode::home(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  const aerotech::MoveResult r = stage_->home();
  res.success = r.success();
  res.message = r.message;
  return true;
}

void StageControllerNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  using diagnostic_msgs::DiagnosticStatus;
  std::lock_guard<std::mutex> lock(status_mutex_);
  const auto& c = stage_->config();
  if (!health_known_) {
    status.summaryf(DiagnosticStatus::ERROR, "no feedback: %s", last_error_.c_str());
  } else if (health_.rotary_faults || health_.slide_faults) {
    status.summaryf(DiagnosticStatus::ERROR, "axis fault: %s %s, %s %s", c.rotary.axis.c_str(),
                    aerotech::describeFaults(health_.rotary_faults).c_str(), c.slide.axis.c_str(),
                    aerotech::describeFaults(health_.slide_faults).c_str());
  } else if (!ready_) {
    status.summary(DiagnosticStatus::WARN, "setting up (enable, home)");
  } else {
    status.summary(DiagnosticStatus::OK, "ready");
  }
  status.add("rotary status", health_.rotary_status.describe());
  status.add("slide status", health_.slide_status.describe());
  status.add("rotary faults", aerotech::describeFaults(health_.rotary_faults));
  status.add("slide faults", aerotech::describeFaults(health_.slide_faults));
  status.add("joint state rate (Hz)", feedback_rate_);
  status.add("reconnects", stage_->reconnects());
  status.add("last error", last_error_);
}

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
