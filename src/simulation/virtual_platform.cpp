#include "dormant_tree_modeling/simulation/virtual_platform.h"

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/simulation/simulated_scan_source.h"

namespace dormant_tree_modeling {
namespace simulation {

VirtualPlatform::VirtualPlatform(const Scene& scene, const VirtualPlatformConfig& o) {
  if (o.scan_frequency_hz != 25.0 && o.scan_frequency_hz != 50.0)
    throw Error(ErrorCode::INVALID_ARGUMENT, "the LMS111 runs at 25 or 50 Hz");
  ensemble_ =
      std::make_shared<emulation::EmulatedEnsemble>(emulation::defaultStageAxes(), o.stage_faults);
  stage_ = std::make_unique<emulation::EnsembleServer>(ensemble_, "127.0.0.1", o.stage_port);

  Lms111Config sensor;
  sensor.range_noise_sigma = o.range_noise_sigma;
  const double period = 1.0 / o.scan_frequency_hz;
  emulation::EnsembleServer* stage = stage_.get();
  auto ensemble = ensemble_;
  setPlatform(o.platform);
  std::shared_ptr<PlatformState> state = platform_;
  const geometry::StageGeometry geometry = o.geometry;
  // The middle beam (135 of the mirror's 360 deg after the first ray) looks at the tree.
  auto pose = [stage, ensemble, state, geometry, period](double) {
    const double t = stage->now() + 0.375 * period;
    const double theta = ensemble->position("X", t) * M_PI / 180.0;
    const double slide_m = ensemble->position("Y", t) / 1000.0;
    Eigen::Isometry3d platform;
    {
      std::lock_guard<std::mutex> lock(state->mutex);
      platform = state->pose;
    }
    return geometry::laserPose(geometry::stagePose(platform, geometry, slide_m), geometry, theta);
  };
  auto source = std::make_shared<SimulatedScanSource>(scene, pose, sensor, o.seed);
  emulation::LmsEmulatorConfig device;
  device.scan.frequency = device.scan.resolution = o.scan_frequency_hz == 25.0 ? 2500 : 5000;
  laser_ = std::make_unique<emulation::LmsServer>(
      std::make_shared<emulation::EmulatedLms111>(device, source, o.laser_faults), o.laser);
}

void VirtualPlatform::setPlatform(const Eigen::Isometry3d& platform) {
  if (!platform.matrix().allFinite())
    throw Error(ErrorCode::INVALID_ARGUMENT, "the platform pose is not finite");
  std::lock_guard<std::mutex> lock(platform_->mutex);
  platform_->pose = platform;
}

Eigen::Isometry3d VirtualPlatform::platform() const {
  std::lock_guard<std::mutex> lock(platform_->mutex);
  return platform_->pose;
}

VirtualPlatform::~VirtualPlatform() {
  stop();
}

void VirtualPlatform::stop() {
  // The laser's scans read the stage: stop the laser first.
  if (laser_)
    laser_->stop();
  if (stage_)
    stage_->stop();
}

}  // namespace simulation
}  // namespace dormant_tree_modeling
