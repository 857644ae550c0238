// Two primaries on opposite sides of the trunk, in one candidate cluster (a crown whose whorls
// fuse at centimetre noise; here a shoot curling around the trunk joins them): a line fitted
// across the trunk through both is no branch, and each is found on its own side.
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
using test::buildTrunk;
using test::lineAngleDeg;

constexpr double DEG = M_PI / 180.0;
constexpr double TRUNK_RADIUS = 0.03;
constexpr double WHORL_Z = 0.9;
constexpr double SHOOT_RADIUS = 0.003;
constexpr double SHOOT_OFF_AXIS = 0.09;  // m: inside the candidate shell (5 cm off the surface)
// One line through the trunk axis: the first primary rises 20 deg towards +x, the second
// leaves the other side, falling 20 deg towards -x.
const Eigen::Vector3d FIRST = Eigen::Vector3d(std::cos(20 * DEG), 0, std::sin(20 * DEG));
const Eigen::Vector3d SECOND = -FIRST;

/// Where a primary leaving the trunk axis at the whorl along `dir` reaches `off_axis` metres.
Eigen::Vector3d along(const Eigen::Vector3d& dir, double off_axis) {
  return Eigen::Vector3d(0, 0, WHORL_Z) + dir * (off_axis / dir.head<2>().norm());
}

/// A thin shoot from the first primary around the trunk (through +y) to the second, in the
/// candidate shell: it joins both into one cluster. One ring of returns every 9 mm, so that it
/// holds few of the candidate's points.
void addShoot(Points& pts) {
  const Eigen::Vector3d from = along(FIRST, SHOOT_OFF_AXIS), to = along(SECOND, SHOOT_OFF_AXIS);
  const int steps = 30, around = 8;
  for (int i = 0; i <= steps; ++i) {
    const double t = static_cast<double>(i) / steps, phi = M_PI * t;
    const Eigen::Vector3d c(SHOOT_OFF_AXIS * std::cos(phi), SHOOT_OFF_AXIS * std::sin(phi),
                            from.z() + t * (to.z() - from.z()));
    const Eigen::Vector3d u(std::cos(phi), std::sin(phi), 0), v(0, 0, 1);
    for (int k = 0; k < around; ++k) {
      const double psi = 2 * M_PI * k / around;
      pts.push_back(c + SHOOT_RADIUS * (std::cos(psi) * u + std::sin(psi) * v));
    }
  }
}

TEST(BranchSpan, AFitAcrossTheTrunkThroughTwoPrimariesIsNoBranch) {
  Points pts;
  addCylinder(pts, {0, 0, 0}, {0, 0, 1}, TRUNK_RADIUS, 1.5);
  const std::size_t trunk_points = pts.size();
  // The first is thicker and longer, so the fused candidate lies mostly on its side and its
  // principal axis runs along both.
  addCylinder(pts, along(FIRST, TRUNK_RADIUS), FIRST, 0.015, 0.45);
  addCylinder(pts, along(SECOND, TRUNK_RADIUS), SECOND, 0.008, 0.30);
  addShoot(pts);
  auto [region, config, trunk] = buildTrunk(pts, trunk_points);
  std::vector<RejectedBranch> rejected;
  const auto kept = modelBranches(pts, PointIndex(pts), trunk, region, config, &rejected);
  ASSERT_EQ(kept.size(), 2u);
  for (const auto& b : kept) {
    const Eigen::Vector3d own = b.cylinder.center.x() > 0 ? FIRST : SECOND;
    EXPECT_LT(lineAngleDeg(b.cylinder.axis, own), 5.0);
    // Its points lie on its own side of the trunk.
    EXPECT_GT(b.cylinder.center.head<2>().dot(own.head<2>().normalized()), TRUNK_RADIUS);
  }
  EXPECT_NE(kept[0].cylinder.center.x() > 0, kept[1].cylinder.center.x() > 0);
}

}  // namespace
}  // namespace modeling
}  // namespace dormant_tree_modeling
