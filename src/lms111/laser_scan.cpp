#include "dormant_tree_modeling/lms111/laser_scan.h"

#include <cmath>
#include <limits>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace lms111 {

LaserScanData toLaserScan(const ScanTelegram& scan, double range_min, double range_max) {
  const ScanChannel* dist = scan.channel("DIST1");
  if (!dist)
    throw Error(ErrorCode::PARSE_ERROR, "scan telegram without a DIST1 channel");
  const ScanChannel* rssi = scan.channel("RSSI1");
  if (rssi &&
      (rssi->values.size() != dist->values.size() || rssi->start_angle != dist->start_angle ||
       rssi->angular_step != dist->angular_step)) {
    throw Error(ErrorCode::PARSE_ERROR, "RSSI1 channel (" + std::to_string(rssi->values.size()) +
                                            " values) does not match DIST1 (" +
                                            std::to_string(dist->values.size()) + " values)");
  }
  constexpr double DEG = M_PI / 180.0;
  LaserScanData out;
  out.angle_increment = dist->stepDeg() * DEG;
  out.angle_min = (dist->startAngleDeg() + DEVICE_TO_ROS_ANGLE_DEG) * DEG;
  const std::size_t n = dist->values.size();
  out.angle_max = out.angle_min + out.angle_increment * (n > 0 ? n - 1 : 0);
  out.time_increment = scan.timeIncrement();
  out.scan_time = scan.scan_frequency > 0 ? 100.0 / scan.scan_frequency : 0.0;
  out.range_min = range_min;
  out.range_max = range_max;
  out.ranges.resize(n);
  const float inf = std::numeric_limits<float>::infinity();
  for (std::size_t i = 0; i < n; ++i) {
    // 0 is the device's "no echo"; REP 117 reports that, and anything beyond the range, as
    // +Inf and a return too close to measure as -Inf. Raw values 1 ... 15 are the device's
    // codes for an invalid measurement (dazzled, reserved), not distances: NaN.
    const double m = (dist->values[i] * static_cast<double>(dist->scale) + dist->offset) * 1e-3;
    if (dist->values[i] > 0 && dist->values[i] < FIRST_VALID_DISTANCE)
      out.ranges[i] = std::numeric_limits<float>::quiet_NaN();
    else if (dist->values[i] == 0 || m > range_max)
      out.ranges[i] = inf;
    else if (m < range_min)
      out.ranges[i] = -inf;
    else
      out.ranges[i] = static_cast<float>(m);
  }
  if (rssi) {
    out.intensities.resize(n);
    for (std::size_t i = 0; i < n; ++i)
      out.intensities[i] = static_cast<float>(rssi->values[i] * rssi->scale + rssi->offset);
  }
  return out;
}

}  // namespace lms111
}  // namespace dormant_tree_modeling
