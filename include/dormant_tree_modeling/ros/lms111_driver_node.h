#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <diagnostic_updater/publisher.h>
#include <ros/ros.h>
#include <sensor_msgs/LaserScan.h>

#include <memory>

#include "dormant_tree_modeling/lms111/driver.h"

#include "dormant_tree_modeling/ros/node_support.h"

namespace dormant_tree_modeling {
namespace ros_layer {

/// @brief ROS wrapper of the LMS111 driver.
///
/// Publishes `scan` (sensor_msgs/LaserScan: ROS angles, -135 ... 135 deg for the full range;
/// stamped at the first ray from the device clock mapped to ROS time; REP 117 for readings
/// without a range; intensities when `~rssi`) and `/diagnostics` (connection state, device
/// status with pollution warnings, scan rate against the configured one, scan-counter gaps,
/// parse errors). Parameters (private): `~host`, `~port`, `~protocol` (cola_a | cola_b),
/// `~scan_frequency` (Hz), `~angular_resolution` (deg), `~start_angle`, `~stop_angle` (deg,
/// device convention), `~rssi`, `~frame_id`, `~range_min`, `~range_max` (m),
/// `~connect_timeout`, `~reply_timeout` (s), `~scan_timeout_periods`, `~ready_timeout`,
/// `~reconnect_min`, `~reconnect_max` (s); defaults and units in config/lms111_driver.yaml.
class Lms111DriverNode {
 public:
  /// @throws Error INVALID_ARGUMENT for a bad parameter
  Lms111DriverNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  ~Lms111DriverNode();
  Lms111DriverNode(const Lms111DriverNode&) = delete;
  Lms111DriverNode& operator=(const Lms111DriverNode&) = delete;

 private:
  void publish(const lms111::StampedScan& scan);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  std::string frame_id_;
  double range_min_, range_max_;
  ros::Publisher scan_pub_;
  double expected_rate_;
  double min_rate_, max_rate_;
  std::unique_ptr<diagnostic_updater::FrequencyStatus> rate_;
  // After the rate it reports: destroyed first, so its timer never reads a destroyed rate.
  NodeDiagnostics diagnostics_;
  std::unique_ptr<lms111::Lms111Driver> driver_;
};

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
