#pragma once

#include <Eigen/Geometry>
#include <functional>
#include <memory>

#include "dormant_tree_modeling/emulation/scan_source.h"
#include "dormant_tree_modeling/simulation/lms111_model.h"
#include "dormant_tree_modeling/simulation/ray_caster.h"
#include "dormant_tree_modeling/simulation/scene.h"

namespace dormant_tree_modeling {
namespace simulation {

/// @brief Scans a synthetic scene with the simulation's LMS111 sensor model (beam footprint,
/// mixed pixels, noise, dropouts) from a laser pose that may change with time, e.g. driven by
/// an emulated rotary stage.
class SimulatedScanSource : public emulation::ScanSource {
 public:
  /// @brief Laser pose in the scene frame at a device time (s).
  using PoseFunction = std::function<Eigen::Isometry3d(double time_s)>;

  /// @param scene the scene to scan (copied into the ray caster)
  /// @param pose laser pose over time
  /// @param sensor noise, bias and beam model; its angles and frequency are replaced by each
  ///        scan's geometry
  /// @param seed noise seed; equal seeds and scan indices give equal scans
  SimulatedScanSource(const Scene& scene, PoseFunction pose, Lms111Config sensor = {},
                      std::uint64_t seed = 1);

  emulation::ScanContent scan(const emulation::ScanGeometry& geometry, double time_s,
                              std::uint64_t index) override;

  /// @brief A fixed laser pose looking at the scene's target tree from the front, the scan
  /// plane vertical: `distance` m in front of the trunk (y < 0) at `height` m.
  static Eigen::Isometry3d frontView(double distance = 1.5, double height = 1.5);

 private:
  std::unique_ptr<RayCaster> caster_;
  PoseFunction pose_;
  Lms111Config sensor_;
  std::uint64_t seed_;
};

}  // namespace simulation
}  // namespace dormant_tree_modeling
