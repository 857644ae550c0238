#include "dormant_tree_modeling/simulation/simulated_scan_source.h"

#include <algorithm>
#include <cmath>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/geometry/stage_kinematics.h"

namespace dormant_tree_modeling {
namespace simulation {

SimulatedScanSource::SimulatedScanSource(const Scene& scene, PoseFunction pose, Lms111Config sensor,
                                         std::uint64_t seed)
    : caster_(std::make_unique<RayCaster>(scene)),
      pose_(std::move(pose)),
      sensor_(sensor),
      seed_(seed) {
  if (!pose_)
    throw Error(ErrorCode::INVALID_ARGUMENT, "a simulated scan source needs a pose function");
}

emulation::ScanContent SimulatedScanSource::scan(const emulation::ScanGeometry& geometry,
                                                 double time_s, std::uint64_t index) {
  Lms111Config config = sensor_;
  config.angular_resolution_deg = geometry.step_deg;
  config.scan_frequency_hz = geometry.scan_frequency_hz;
  config.start_angle_deg = geometry.start_angle_deg;
  config.stop_angle_deg = geometry.start_angle_deg + geometry.count * geometry.step_deg;
  const Lms111Model model(*caster_, config);
  Rng rng = Rng::derive(seed_, 11, index);
  const ScanLine line = model.scanLine(pose_(time_s), rng);
  emulation::ScanContent out;
  out.distances_mm.assign(geometry.count, 0);
  out.rssi.assign(geometry.count, 0);
  const int n = std::min<int>(geometry.count, static_cast<int>(line.ranges.size()));
  for (int i = 0; i < n; ++i) {
    const double mm = std::round(line.ranges[i] * 1000.0);
    out.distances_mm[i] = static_cast<std::uint16_t>(std::clamp(mm, 0.0, 65535.0));
    out.rssi[i] = line.rssi[i];
  }
  return out;
}

Eigen::Isometry3d SimulatedScanSource::frontView(double distance, double height) {
  // The platform's x axis points at the tree: from y = -distance that is the scene's +y.
  const Eigen::Isometry3d platform = geometry::platformPose(0.0, -distance, height, M_PI / 2);
  const geometry::StageGeometry geometry;
  return geometry::laserPose(geometry::stagePose(platform, geometry, 0.0), geometry, 0.0);
}

}  // namespace simulation
}  // namespace dormant_tree_modeling
