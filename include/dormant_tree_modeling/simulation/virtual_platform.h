#pragma once

#include <Eigen/Geometry>
#include <memory>
#include <mutex>
#include <string>
#include <vector>

#include "dormant_tree_modeling/aerotech/stage_config.h"
#include "dormant_tree_modeling/emulation/ensemble_server.h"
#include "dormant_tree_modeling/emulation/lms111_server.h"
#include "dormant_tree_modeling/geometry/stage_kinematics.h"
#include "dormant_tree_modeling/simulation/scene.h"

namespace dormant_tree_modeling {

template <typename Config>
class ConfigTable;

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
  /// Mounting: the stage controller's default (config/stage_controller.yaml).
  geometry::StageGeometry geometry = aerotech::StageConfig().geometry;
  emulation::EnsembleFaults stage_faults;
  emulation::LmsFaults laser_faults;
};

/// @brief The virtual platform node's parameters (launch/virtual_platform.launch).
struct VirtualPlatformNodeConfig {
  int lms_port = 2111;              ///< the emulated LMS111's CoLa-A port; 0: any, -1: off
  int lms_b_port = 2112;            ///< CoLa-B
  int aerotech_port = 8000;         ///< the emulated Ensemble
  double scan_frequency_hz = 25.0;  ///< the LMS111's power-up frequency (25 or 50)
  double noise_mm = 12.0;           ///< range noise, 1 sigma
  int seed = 1;
  std::vector<double> platform = {0.0, -1.5, 1.5, 90.0};  ///< start: x, y, z (m), yaw (deg)
  std::string fault_axis;  ///< the emulated stage fails moves of this axis ...
  int fault_on_move = 0;   ///< ... from this move on (0: never)
  std::string scene_frame = "orchard";
  std::string output_dir;  ///< scene.json and truth.json; empty: none
  std::string in_place_service = "/acquisition/platform_in_place";
  double placement_error_m = 0.2;  ///< the virtual operator's error after the first position
  double placement_error_yaw_deg = 8.0;
  double settle_time_s = 0.5;  ///< after a move before the platform reports it is in place
  std::string scene_file;      ///< a scene.json; empty: the preset
  std::string preset = "young_tall_spindle";
  bool follow_goals = false;  ///< drive to the acquisition's platform goals
  std::string goal_topic = "/acquisition/platform_goal";
  /// @throws Error INVALID_ARGUMENT naming the field
  void validate() const;
};

/// @brief The keys of the virtual platform node: its parameters, docs/configuration.md.
const ConfigTable<VirtualPlatformNodeConfig>& virtualPlatformNodeConfigTable();

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
