#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <mutex>
#include <string>

#include "dormant_tree_modeling/emulation/ensemble_server.h"
#include "dormant_tree_modeling/emulation/lms111_server.h"
#include "dormant_tree_modeling/geometry/stage_kinematics.h"
#include "dormant_tree_modeling/simulation/scene.h"

namespace dormant_tree_modeling {
namespace simulation {

/// @brief The scanning platform without hardware (architecture.md `virtual_platform`).
struct VirtualPlatformConfig {
  emulation::LmsServerConfig laser;  ///< ports of the LMS111 (CoLa-A, CoLa-B)
  int stage_port = 8000;             ///< port of the Ensemble
  double scan_frequency_hz = 25.0;   ///< the LMS111's power-up frequency (25 or 50)
  double range_noise_sigma = 0.012;  ///< m
  std::uint64_t seed = 1;            ///< sensor noise
  /// The platform in the scene frame (platformPose); default: 1.5 m in front of the target
  /// tree, facing it, the laser at 1.5 m.
  Eigen::Isometry3d platform = geometry::platformPose(0.0, -1.5, 1.5, M_PI / 2);
  /// Mounting, as config/stage_controller.yaml: the platform frame at the slide's centre.
  geometry::StageGeometry geometry = [] {
    geometry::StageGeometry g;
    g.platform_to_slide_base = Eigen::Vector3d(0.0, -0.3, 0.0);
    return g;
  }();
  emulation::EnsembleFaults stage_faults;
  emulation::LmsFaults laser_faults;
};

/// @brief Serves an LMS111 and an Aerotech Ensemble (rotary stage X in deg, 600 mm slide Y in
/// mm) on loopback from one scene: each simulated scan line is taken from the pose the
/// emulated stage is in at the line's middle beam (where the tree is).
class VirtualPlatform {
 public:
  /// @throws Error IO_FAILURE when a port cannot be bound, INVALID_ARGUMENT for bad options
  VirtualPlatform(const Scene& scene, const VirtualPlatformConfig& options);
  ~VirtualPlatform();
  int laserPort() const { return laser_->colaAPort(); }
  int laserColaBPort() const { return laser_->colaBPort(); }
  int stagePort() const { return stage_->port(); }
  /// @brief Move the platform (scene frame, as platformPose); scan lines after the call see
  /// the new pose. Thread-safe.
  void setPlatform(const Eigen::Isometry3d& platform);
  /// @brief The platform's current pose in the scene frame.
  Eigen::Isometry3d platform() const;
  void stop();

 private:
  /// Read by the laser's scan thread, written by whoever drives the platform.
  struct PlatformState {
    mutable std::mutex mutex;
    Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  };
  std::shared_ptr<PlatformState> platform_ = std::make_shared<PlatformState>();
  std::shared_ptr<emulation::EmulatedEnsemble> ensemble_;
  std::unique_ptr<emulation::EnsembleServer> stage_;
  std::unique_ptr<emulation::LmsServer> laser_;
};

}  // namespace simulation
}  // namespace dormant_tree_modeling
