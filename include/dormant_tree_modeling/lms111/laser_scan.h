#pragma once

#include <vector>

#include "dormant_tree_modeling/lms111/scan_telegram.h"

namespace dormant_tree_modeling {
namespace lms111 {

/// @brief The content of a sensor_msgs/LaserScan, ROS-free: ROS angle convention (x ahead,
/// counter-clockwise, so the device's -45 ... 225 deg become -135 ... 135 deg), metres and
/// REP 117 for readings without a valid range.
struct LaserScanData {
  double angle_min = 0, angle_max = 0, angle_increment = 0;  ///< rad
  double time_increment = 0;                                 ///< s between two rays
  double scan_time = 0;                                      ///< s between two scans
  double range_min = 0, range_max = 0;                       ///< m
  std::vector<float> ranges;       ///< m; +Inf no echo or beyond range_max, -Inf below range_min
  std::vector<float> intensities;  ///< RSSI, empty when the telegram has no RSSI1 channel
};

/// @brief Offset between the device's angles and ROS's: ROS = device - 90 deg.
constexpr double DEVICE_TO_ROS_ANGLE_DEG = -90.0;

/// @brief Convert a scan telegram.
/// @param range_min, range_max the device's valid range, m (LMS111: 0.5 and 20)
/// @throws Error PARSE_ERROR without a DIST1 channel, or with an RSSI1 channel whose count or
///         angles differ from DIST1's
LaserScanData toLaserScan(const ScanTelegram& scan, double range_min, double range_max);

}  // namespace lms111
}  // namespace dormant_tree_modeling
