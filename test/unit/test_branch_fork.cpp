// A primary with a side arm (a secondary, a shoot at its tip) forking off it inside the fit
// window: the branch is fitted along the primary, not along the arm, and the arm is no branch,
// also when noise leaves the arm's returns cut off from the trunk once the primary is out.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <vector>

#include "built_scene.h"
#include "dormant_tree_modeling/modeling/branch_model.h"
#include "dormant_tree_modeling/modeling/point_index.h"

namespace dormant_tree_modeling {
namespace modeling {
namespace {

using test::addCylinder;
using test::addIsotropicNoise;
using test::buildTrunk;
using test::lineAngleDeg;

constexpr double DEG = M_PI / 180.0;
const Eigen::Vector3d SURFACE(0.03, 0, 0.9);  // where the primary leaves the 3 cm trunk
const Eigen::Vector3d OUT = Eigen::Vector3d(1, 0, 0.1).normalized();
constexpr double FORK_OFF = 0.10;  // m off the trunk surface, inside the fit window

/// The direction `azimuth_deg` around the vertical from OUT, rising as OUT does.
Eigen::Vector3d turned(double azimuth_deg) {
  return Eigen::Vector3d(std::cos(azimuth_deg * DEG), std::sin(azimuth_deg * DEG), 0.1)
      .normalized();
}

/// The trunk, a 20 cm primary and a 30 cm arm leaving it 10 cm out at `arm_azimuth_deg`: the
/// arm is longer than what follows of the primary, so a line along it holds more returns.
Points forkedScene(double arm_azimuth_deg, std::size_t* trunk_points) {
  Points pts;
  addCylinder(pts, {0, 0, 0}, {0, 0, 1}, 0.03, 1.5);
  *trunk_points = pts.size();
  addCylinder(pts, SURFACE, OUT, 0.006, 0.20);
  addCylinder(pts, SURFACE + FORK_OFF * OUT, turned(arm_azimuth_deg), 0.005, 0.30);
  return pts;
}

TEST(BranchFork, APrimaryIsFittedAlongItselfNotAlongItsSideArm) {
  std::size_t trunk_points = 0;
  const Points pts = forkedScene(30.0, &trunk_points);
  auto [region, config, trunk] = buildTrunk(pts, trunk_points);
  const auto kept = modelBranches(pts, PointIndex(pts), trunk, region, config, nullptr);
  // One branch: the arm, searched again once the primary is taken out, is no primary.
  ASSERT_EQ(kept.size(), 1u);
  // The arm's line misses the trunk axis by 6.5 cm; the primary's passes through it.
  EXPECT_LT(lineAngleDeg(kept[0].cylinder.axis, OUT), 5.0);
  EXPECT_NEAR(kept[0].attachment.z(), SURFACE.z(), 0.02);
  EXPECT_TRUE(kept[0].reaches_surface);
}

/// A thin primary (4 mm radius, `primary_length_m` long) with a 2 mm arm leaving it
/// `fork_off_m` out, 56 degrees around from it and rising (the secondary of a young tree's top
/// primary), every point moved by isotropic noise of `sigma_m`.
Points noisyThinFork(double fork_off_m, double primary_length_m, double sigma_m, unsigned seed,
                     std::size_t* trunk_points) {
  Points pts;
  addCylinder(pts, {0, 0, 0}, {0, 0, 1}, 0.03, 1.5);
  *trunk_points = pts.size();
  addCylinder(pts, SURFACE, OUT, 0.004, primary_length_m);
  const Eigen::Vector3d arm =
      Eigen::Vector3d(std::cos(56.0 * DEG), std::sin(56.0 * DEG), 0.3).normalized();
  addCylinder(pts, SURFACE + fork_off_m * OUT, arm, 0.002, 0.20);
  addIsotropicNoise(pts, sigma_m, seed);
  return pts;
}

TEST(BranchFork, AnArmCutOffFromTheTrunkByThePrimarysExtractionIsNoBranch) {
  // Over 24 seeded scenes. Once the primary is out, the arm's returns start off the trunk
  // surface; its line leads past the trunk, so the returns on its way back are the primary's,
  // not a near part of its own that a crossing branch took out. Kept as cut off, it stood as a
  // second branch in 3 of these scenes.
  for (const double sigma : {0.008, 0.012})
    for (const double fork_off : {0.08, 0.10})
      for (const double primary_length : {0.20, 0.35})
        for (const unsigned seed : {1u, 2u, 3u}) {
          std::size_t trunk_points = 0;
          const Points pts = noisyThinFork(fork_off, primary_length, sigma, seed, &trunk_points);
          auto [region, config, trunk] = buildTrunk(pts, trunk_points);
          config.noise.sigma_m = sigma;
          const auto kept = modelBranches(pts, PointIndex(pts), trunk, region, config, nullptr);
          SCOPED_TRACE(testing::Message() << "noise " << sigma << " fork " << fork_off
                                          << " primary " << primary_length << " seed " << seed);
          ASSERT_FALSE(kept.empty());
          EXPECT_LT(lineAngleDeg(kept[0].cylinder.axis, OUT), 15.0);
          for (const auto& k : kept)
            EXPECT_TRUE(k.reaches_surface);
        }
}

}  // namespace
}  // namespace modeling
}  // namespace dormant_tree_modeling
