// A whorl's branch bases lie in the trunk's slices and widen their circles. Once the branches
// are found, the points nearer a branch's surface than the trunk's are its base; the trunk
// measured again without them reads its own radius.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <iterator>
#include <random>
#include <vector>

#include "built_scene.h"
#include "dormant_tree_modeling/modeling/branch_model.h"
#include "dormant_tree_modeling/modeling/point_index.h"

namespace dormant_tree_modeling {
namespace modeling {
namespace {

using test::addCylinder;
using test::buildTrunk;

constexpr double DEG = M_PI / 180.0;
constexpr double WHORL_Z = 0.9;
constexpr int WHORL_BRANCHES = 6;

/// A vertical trunk 1.5 m tall and a whorl of branches leaving it at 0.9 m.
struct WhorlShape {
  double trunk_radius;
  double branch_radius;
  double rise;   ///< of the branches (rad)
  double reach;  ///< of the trunk region off the trunk axis (m): trunkReach of the trunk
  double noise;  ///< sigma of each coordinate (m), 0: the built surface
};

/// buildTrunk's 3 cm trunk, noise free, with six 12 mm branches rising 30 deg.
constexpr WhorlShape BUILT{0.03, 0.012, 30 * DEG, 0.09, 0.0};
/// A leader's top under noise half its radius, with six 10 mm branches rising 50 deg: the
/// slice through the whorl holds five times the trunk's returns.
constexpr WhorlShape NOISY{0.012, 0.010, 50 * DEG, 0.062, 0.006};

struct Whorl {
  Points pts;
  std::size_t trunk_points = 0;
  std::vector<int> region;  ///< every point within the shape's reach of the trunk axis
};

Whorl buildWhorl(const WhorlShape& shape) {
  Whorl w;
  addCylinder(w.pts, {0, 0, 0}, {0, 0, 1}, shape.trunk_radius, 1.5);
  w.trunk_points = w.pts.size();
  for (int i = 0; i < WHORL_BRANCHES; ++i) {
    const double phi = 2 * M_PI * i / WHORL_BRANCHES;
    const Eigen::Vector3d dir(std::cos(shape.rise) * std::cos(phi),
                              std::cos(shape.rise) * std::sin(phi), std::sin(shape.rise));
    addCylinder(w.pts, Eigen::Vector3d(0, 0, WHORL_Z) + shape.trunk_radius * dir, dir,
                shape.branch_radius, 0.45);
  }
  if (shape.noise > 0.0) {
    std::mt19937 rng(7);
    std::normal_distribution<double> noise(0.0, shape.noise);
    for (auto& p : w.pts)
      p += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
  }
  for (std::size_t k = 0; k < w.pts.size(); ++k) {
    if (w.pts[k].head<2>().norm() < shape.reach)
      w.region.push_back(static_cast<int>(k));
  }
  return w;
}

/// The largest error of a slice's corrected radius within 10 cm of the whorl (m).
double worstWhorlSlice(const TrunkModel& trunk, double slice_height, double radius) {
  double worst = 0.0;
  for (const auto& sl : trunk.slices) {
    const double z = sl.s0 + 0.5 * slice_height;
    if (sl.has_circle && std::abs(z - WHORL_Z) < 0.1)
      worst = std::max(worst, std::abs(sl.corrected_radius - radius));
  }
  return worst;
}

TEST(BranchBases, OnlyBranchReturnsBeyondTheTrunkBandAreBases) {
  const Whorl w = buildWhorl(BUILT);
  const auto [trunk_region, config, trunk] = buildTrunk(w.pts, w.trunk_points);
  const auto branches = modelBranches(w.pts, PointIndex(w.pts), trunk, w.region, config);
  ASSERT_EQ(branches.size(), static_cast<std::size_t>(WHORL_BRANCHES));
  const double band = trunkSurfaceBand(trunk, config);
  const auto bases = branchBasePoints(w.pts, w.region, trunk, branches, band);
  ASSERT_FALSE(bases.empty());
  std::vector<char> is_base(w.pts.size(), 0);
  for (const int k : bases) {
    EXPECT_GE(k, static_cast<int>(w.trunk_points)) << "a trunk return taken for a branch base";
    is_base[k] = 1;
  }
  // Every branch return between the trunk's band and the fits' near ends is a base.
  for (const auto& b : branches) {
    const Eigen::Vector3d near_end = b.cylinder.center - 0.5 * b.cylinder.length * b.cylinder.axis;
    for (const int k : w.region) {
      const Eigen::Vector3d& p = w.pts[k];
      if (k < static_cast<int>(w.trunk_points) || (p - b.attachment).dot(b.cylinder.axis) < 0.0)
        continue;
      const bool before_the_fit = (p - near_end).dot(b.cylinder.axis) < 0.0;
      const bool beside_this_branch = axisDistance(b.cylinder, p) < 2 * BUILT.branch_radius;
      if (before_the_fit && beside_this_branch &&
          p.head<2>().norm() > BUILT.trunk_radius + 1.5 * band) {
        EXPECT_TRUE(is_base[k]) << "a base return " << 1000 * p.head<2>().norm()
                                << " mm off the trunk axis was left in the trunk";
      }
    }
  }
}

TEST(BranchBases, TheTrunkMeasuredWithoutThemReadsItsOwnRadiusAtTheWhorl) {
  const Whorl w = buildWhorl(NOISY);
  ModelerConfig config;
  config.noise.sigma_m = NOISY.noise;
  config = stageConfig(config);
  const std::vector<Eigen::Vector3d> axis{{0, 0, 0}, {0, 0, 1.5}};
  const TrunkModel with_bases = modelTrunk(w.pts, w.region, axis, NOISY.trunk_radius, config);
  const auto branches = modelBranches(w.pts, PointIndex(w.pts), with_bases, w.region, config);
  ASSERT_EQ(branches.size(), static_cast<std::size_t>(WHORL_BRANCHES));
  const auto bases =
      branchBasePoints(w.pts, w.region, with_bases, branches, trunkSurfaceBand(with_bases, config));
  std::vector<int> region;
  std::set_difference(w.region.begin(), w.region.end(), bases.begin(), bases.end(),
                      std::back_inserter(region));
  const TrunkModel without =
      modelTrunk(w.pts, region, axis, NOISY.trunk_radius, config, {}, &with_bases);
  const double h = config.trunk.slice_height_m;
  // With the bases the whorl's slice takes in the branches (30 mm for the 12 mm trunk);
  // without, it reads within the slices' scatter elsewhere on the trunk (up to 3 mm).
  EXPECT_GT(worstWhorlSlice(with_bases, h, NOISY.trunk_radius), 0.010);
  EXPECT_LT(worstWhorlSlice(without, h, NOISY.trunk_radius), 0.004);
  // The line, readings and partitions of the first model are kept.
  EXPECT_EQ(without.centerline.vertices(), with_bases.centerline.vertices());
  EXPECT_EQ(without.noise_sigma, with_bases.noise_sigma);
  EXPECT_EQ(without.table_sigma, with_bases.table_sigma);
  EXPECT_EQ(without.partitions, with_bases.partitions);
}

}  // namespace
}  // namespace modeling
}  // namespace dormant_tree_modeling
