// The Hough transform over rays leaving a trunk axis, and fused whorls parted along them.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <numeric>

#include "dormant_tree_modeling/common/random.h"
#include "dormant_tree_modeling/modeling/branch_model.h"
#include "dormant_tree_modeling/modeling/branch_rays.h"
#include "dormant_tree_modeling/modeling/trunk_model.h"

namespace dormant_tree_modeling {
namespace modeling {
namespace {

constexpr double DEG = M_PI / 180.0;

Eigen::Vector3d direction(double azimuth_deg, double elevation_deg) {
  return {std::cos(elevation_deg * DEG) * std::cos(azimuth_deg * DEG),
          std::cos(elevation_deg * DEG) * std::sin(azimuth_deg * DEG),
          std::sin(elevation_deg * DEG)};
}

/// Noisy points along a ray from (0, 0, height), from 5 to 35 cm off the axis.
void addRay(Points& pts, Rng& rng, double height, const Eigen::Vector3d& dir, int n, double sigma) {
  for (int i = 0; i < n; ++i) {
    const double rho = rng.uniform(0.05, 0.35);
    const Eigen::Vector3d along = rho / std::hypot(dir.x(), dir.y()) * dir;
    pts.push_back(
        Eigen::Vector3d(0, 0, height) + along +
        Eigen::Vector3d(rng.normal(0, sigma), rng.normal(0, sigma), rng.normal(0, sigma)));
  }
}

Cylinder verticalTrunk() {
  Cylinder c;
  c.center = {0, 0, 1};
  c.axis = {0, 0, 1};
  c.radius = 0.03;
  c.length = 2;
  return c;
}

TEST(StrongestRay, FindsTheBestReturnedOfThreeRays) {
  Rng rng(5);
  Points pts;
  addRay(pts, rng, 1.00, direction(30, 20), 600, 0.004);
  addRay(pts, rng, 1.02, direction(55, 10), 400, 0.004);   // 25 deg beside it
  addRay(pts, rng, 0.90, direction(-120, 0), 300, 0.004);  // across the trunk
  const auto ray = strongestRay(pts, verticalTrunk(), -30.0, 75.0);
  ASSERT_TRUE(ray);
  // A seed for the fit that follows: within a cell (5 deg) of the ray in each angle.
  EXPECT_GT(ray->direction.dot(direction(30, 20)), std::cos(7.5 * DEG));
  EXPECT_NEAR(ray->origin.z(), 1.0, 0.03);
  EXPECT_NEAR(ray->origin.head<2>().norm(), 0.0, 1e-12);
  EXPECT_GE(ray->votes, 500);
  EXPECT_NEAR(rayDistance(*ray, Eigen::Vector3d(0, 0, 0.5)), 0.5, 0.03) << "behind the origin";
}

TEST(StrongestRay, NothingOffTheAxisIsNoRay) {
  EXPECT_FALSE(strongestRay({}, verticalTrunk(), -30.0, 75.0));
  EXPECT_FALSE(strongestRay({{0, 0, 0.5}, {0, 0, 1.5}}, verticalTrunk(), -30.0, 75.0));
}

TEST(BranchModel, AFusedWhorlAtCentimetreNoiseIsPartedAlongItsRays) {
  // Three thin branches leave the trunk at one height 28 deg apart; at 12 mm noise they are one
  // cluster near the trunk, and halves by position cut across them.
  Rng rng(11);
  Points pts;
  for (int i = 0; i < 30000; ++i) {
    const double a = rng.uniform(0.0, 2.0 * M_PI), r = 0.03 + rng.normal(0.0, 0.01);
    pts.push_back({r * std::cos(a), r * std::sin(a), rng.uniform(0.0, 2.0)});
  }
  std::vector<int> region(pts.size());
  std::iota(region.begin(), region.end(), 0);
  const double azimuths[] = {0.0, 28.0, 56.0};
  for (const double az : azimuths)
    addRay(pts, rng, 1.0, direction(az, 15), 1500, 0.012);
  ModelerConfig config;
  config.noise.sigma_m = 0.012;
  const TrunkModel trunk = modelTrunk(pts, region, {{0, 0, 0}, {0, 0, 2}}, 0.03, config);
  const PointIndex index(pts);
  const auto found = [&](const std::vector<BranchFit>& branches) {
    int n = 0;
    for (const double az : azimuths) {
      for (const auto& b : branches)
        n += b.cylinder.axis.dot(direction(az, 15)) > std::cos(10 * DEG);
    }
    return n;
  };
  const auto parted = modelBranches(pts, index, trunk, region, config);
  EXPECT_EQ(found(parted), 3);
  EXPECT_EQ(parted.size(), 3u);
  config.branches.ray_split = false;
  EXPECT_LT(found(modelBranches(pts, index, trunk, region, config)), 3);
}

}  // namespace
}  // namespace modeling
}  // namespace dormant_tree_modeling
