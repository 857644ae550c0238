#include "dormant_tree_modeling/ros/lms111_driver_node.h"

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/lms111/laser_scan.h"
#include "dormant_tree_modeling/ros/node_support.h"

namespace dormant_tree_modeling {
namespace ros_layer {

namespace {

// The scan rate counts as healthy within 2 % of the configured frequency.
constexpr double RATE_TOLERANCE = 0.02;
constexpr int RATE_WINDOW = 50;

}  // namespace

Lms111DriverNode::Lms111DriverNode(ros::NodeHandle& nh, ros::NodeHandle& pnh) {
  const auto node_config = readParameters(pnh, lms111::driverNodeConfigTable());
  node_config.validate();
  const lms111::DriverConfig& config = node_config.device;
  frame_id_ = node_config.frame_id;
  range_min_ = node_config.range_min_m;
  range_max_ = node_config.range_max_m;
  scan_pub_ = nh.advertise<sensor_msgs::LaserScan>("scan", 10);

  expected_rate_ = config.scan_frequency_hz;
  min_rate_ = expected_rate_ * (1.0 - RATE_TOLERANCE);
  max_rate_ = expected_rate_ * (1.0 + RATE_TOLERANCE);
  rate_ = std::make_unique<diagnostic_updater::FrequencyStatus>(
      diagnostic_updater::FrequencyStatusParam(&min_rate_, &max_rate_, 0.0, RATE_WINDOW),
      "scan rate");
  diagnostics_.add(*rate_);
  diagnostics_.add("device", this, &Lms111DriverNode::diagnose);
  diagnostics_.start(nh, "LMS111 " + config.host + ":" + std::to_string(config.port));

  driver_ = std::make_unique<lms111::Lms111Driver>(
      config, [this](const lms111::StampedScan& s) { publish(s); },
      [](int severity, const std::string& m) {
        if (severity >= 2)
          ROS_ERROR("%s", m.c_str());
        else if (severity == 1)
          ROS_WARN("%s", m.c_str());
        else
          ROS_INFO("%s", m.c_str());
      },
      [] { return ros::Time::now().toSec(); });
  driver_->start();
}

Lms111DriverNode::~Lms111DriverNode() {
  driver_->stop();
}

void Lms111DriverNode::publish(const lms111::StampedScan& scan) {
  lms111::LaserScanData data;
  try {
    data = lms111::toLaserScan(scan.telegram, range_min_, range_max_);
  } catch (const Error& e) {
    ROS_WARN_THROTTLE(5.0, "LMS111 scan dropped: %s", e.what());
    return;
  }
  sensor_msgs::LaserScan msg;
  msg.header.stamp = ros::Time(scan.stamp_s);
  msg.header.frame_id = frame_id_;
  msg.angle_min = static_cast<float>(data.angle_min);
  msg.angle_max = static_cast<float>(data.angle_max);
  msg.angle_increment = static_cast<float>(data.angle_increment);
  msg.time_increment = static_cast<float>(data.time_increment);
  msg.scan_time = static_cast<float>(data.scan_time);
  msg.range_min = static_cast<float>(data.range_min);
  msg.range_max = static_cast<float>(data.range_max);
  msg.ranges = std::move(data.ranges);
  msg.intensities = std::move(data.intensities);
  scan_pub_.publish(msg);
  rate_->tick();
}

void Lms111DriverNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  using diagnostic_msgs::DiagnosticStatus;
  const lms111::DriverStatistics s = driver_->statistics();
  if (s.state != lms111::DriverState::STREAMING) {
    status.summaryf(DiagnosticStatus::ERROR, "not streaming (%s): %s",
                    lms111::driverStateName(s.state), s.last_error.c_str());
  } else if (s.device_status == 1 || s.device_status == 5) {
    status.summary(DiagnosticStatus::ERROR, s.device_status == 5 ? "device reports pollution error"
                                                                 : "device reports an error");
  } else if (s.device_status == 2) {
    status.summary(DiagnosticStatus::WARN, "device reports a pollution warning: clean the window");
  } else {
    status.summary(DiagnosticStatus::OK, "streaming");
  }
  status.add("state", lms111::driverStateName(s.state));
  status.add("device", s.device_ident);
  status.add("device status", static_cast<int>(s.device_status));
  status.add("scans", s.scans);
  status.add("scan counter gaps", s.scan_gaps);
  status.add("parse errors", s.parse_errors);
  status.add("other events", s.events);
  status.add("discarded bytes", s.discarded_bytes);
  status.add("successful start-ups", s.connects);
  status.add("failures", s.failures);
  status.add("last error", s.last_error);
}

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
