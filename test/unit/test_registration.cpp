// Registration: point-to-plane ICP recovers known relative poses of simulated views.
#include <gtest/gtest.h>

#include <cmath>

#include "dormant_tree_modeling/acquisition/range_image.h"
#include "dormant_tree_modeling/acquisition/target_isolation.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/registration/icp.h"
#include "dormant_tree_modeling/simulation/orchard_generator.h"
#include "dormant_tree_modeling/simulation/ray_caster.h"
#include "dormant_tree_modeling/simulation/view_simulator.h"

namespace dormant_tree_modeling {
namespace registration {
namespace {

// The target tree's returns of one view, in that view's rotary_stage frame.
Points viewOfTree(const simulation::Lms111Model& model, const Eigen::Isometry3d& stage, int index) {
  acquisition::ViewPlanConfig sweep;
  sweep.theta_step_deg = 0.9;
  const auto view =
      simulation::simulateView(model, stage, acquisition::StageGeometry{}, sweep, 7, index, 2);
  Points pts;
  for (int i = 0; i < view.image.rows; ++i) {
    for (int j = 0; j < view.image.cols; ++j) {
      const float rho = view.image.at(i, j);
      const auto& label = view.labels[static_cast<std::size_t>(i) * view.image.cols + j];
      if (!(rho > 0.0f) || label.object != 0 || label.part > simulation::Part::MINOR)
        continue;
      double x, y, z;
      acquisition::sphericalToCartesian(rho, view.image.theta(i, j), view.image.phi(j), x, y, z);
      pts.emplace_back(x, y, z);
    }
  }
  return pts;
}

double angleDeg(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  return Eigen::AngleAxisd((a.linear().transpose() * b.linear())).angle() * 180.0 / M_PI;
}

TEST(PointToPlaneIcp, RecoversTheRelativePoseOfTwoViews) {
  const simulation::Orchard orchard = simulation::generateOrchard({}, 8);
  const simulation::RayCaster caster(orchard.scene);
  simulation::Lms111Config sensor;
  sensor.angular_resolution_deg = 0.5;
  sensor.scan_frequency_hz = 50.0;
  sensor.range_noise_sigma = 0.006;
  const simulation::Lms111Model model(caster, sensor);
  // Two platform positions 1 m apart along the row, in front of the tree.
  const Eigen::Isometry3d a = acquisition::platformPose(-0.5, -1.5, 1.5, M_PI / 2);
  const Eigen::Isometry3d b = acquisition::platformPose(0.5, -1.5, 1.5, M_PI / 2 + 0.3);
  const Points target = viewOfTree(model, a, 0), source = viewOfTree(model, b, 1);
  ASSERT_GT(target.size(), 1000u);
  ASSERT_GT(source.size(), 1000u);
  const Eigen::Isometry3d truth = a.inverse() * b;  // source (b) -> target (a)
  // A guess 5 cm and 4 deg off.
  Eigen::Isometry3d guess = truth;
  guess.pretranslate(Eigen::Vector3d(0.04, -0.03, 0.0));
  guess.prerotate(Eigen::AngleAxisd(4.0 * M_PI / 180, Eigen::Vector3d::UnitZ()));
  const IcpResult r = alignPointToPlane(source, target, guess);
  const double dt = (r.transform.translation() - truth.translation()).norm();
  const double da = angleDeg(r.transform, truth);
  std::printf(
      "[ INFO ] %zu / %zu points: error %.2f mm, %.3f deg; rmse %.2f mm, overlap %.2f, %d "
      "iterations\n",
      source.size(), target.size(), dt * 1000, da, r.rmse * 1000, r.overlap, r.iterations);
  EXPECT_TRUE(r.converged);
  EXPECT_LT(dt, 0.005);
  EXPECT_LT(da, 0.2);
  EXPECT_GT(r.overlap, 0.3);
  EXPECT_THROW(alignPointToPlane(Points(5), target, guess), Error);
}

}  // namespace
}  // namespace registration
}  // namespace dormant_tree_modeling
