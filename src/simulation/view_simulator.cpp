#include "dormant_tree_modeling/simulation/view_simulator.h"

#include <cmath>

#include "dormant_tree_modeling/common/parallel.h"

namespace dormant_tree_modeling {
namespace simulation {

SimulatedView simulateView(const Lms111Model& model, const Eigen::Isometry3d& stage_pose,
                           const geometry::StageGeometry& geometry,
                           const acquisition::ViewPlanConfig& sweep, std::uint64_t seed,
                           int view_index, int threads) {
  constexpr double DEG = M_PI / 180.0;
  SimulatedView view;
  view.stage_pose = stage_pose;
  auto& image = view.image;
  const int rows = sweep.linesPerView();
  const int cols = model.config().beamCount();
  image.resize(rows, cols);
  image.rssi.assign(image.range.size(), 0);
  image.theta0 = sweep.theta_min_deg * DEG;
  image.theta_step = sweep.theta_step_deg * DEG;
  image.phi0 = model.beamAngle(0);
  image.phi_step = model.config().angular_resolution_deg * DEG;
  view.labels.assign(image.range.size(), Label{});
  parallelFor(
      rows,
      [&](int i) {
        Rng rng = Rng::derive(seed, 7, static_cast<std::uint64_t>(view_index),
                              static_cast<std::uint64_t>(i));
        const auto laser = geometry::laserPose(stage_pose, geometry, image.theta(i));
        const ScanLine line = model.scanLine(laser, rng);
        const std::size_t base = static_cast<std::size_t>(i) * cols;
        for (int j = 0; j < cols; ++j) {
          image.range[base + j] = line.ranges[j];
          image.rssi[base + j] = line.rssi[j];
          view.labels[base + j] = line.labels[j];
        }
      },
      threads);
  return view;
}

}  // namespace simulation
}  // namespace dormant_tree_modeling
