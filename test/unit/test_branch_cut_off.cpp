// Branches whose returns start away from the trunk surface: cut off near the trunk (a crossing
// branch's extraction, an occlusion gap), or a neighbour's tip with air between it and the trunk.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <cmath>
#include <string>
#include <vector>

#include "built_scene.h"
#include "dormant_tree_modeling/modeling/branch_model.h"
#include "dormant_tree_modeling/modeling/point_index.h"

namespace dormant_tree_modeling {
namespace modeling {
namespace {

using test::addCylinder;
using test::buildTrunk;

const Eigen::Vector3d OUT = Eigen::Vector3d(1, 0, 0.1).normalized();
constexpr double BRANCH_RADIUS = 0.01;

/// A level branch leaving the 3 cm trunk at z 0.9 m: its returns from `from` to `to` metres
/// off the trunk surface.
void addBranchPart(Points& pts, double from, double to) {
  const Eigen::Vector3d surface(0.03, 0, 0.9);
  addCylinder(pts, surface + from * OUT, OUT, BRANCH_RADIUS, to - from);
}

int countReason(const std::vector<RejectedBranch>& rejected, BranchRejection reason) {
  int n = 0;
  for (const auto& r : rejected)
    n += r.reason == reason;
  return n;
}

TEST(BranchCutOff, ABranchWhoseReturnsBreakOffNearTheTrunkIsKept) {
  Points pts;
  addCylinder(pts, {0, 0, 0}, {0, 0, 1}, 0.03, 1.5);
  const std::size_t trunk_points = pts.size();
  // 9 cm at the trunk (4 cm of it in the candidate shell: too short alone), 3 cm without
  // returns, then 28 cm: the outer part starts 12 cm off the surface.
  addBranchPart(pts, 0.0, 0.09);
  addBranchPart(pts, 0.12, 0.40);
  auto [region, config, trunk] = buildTrunk(pts, trunk_points);
  const PointIndex index(pts);
  std::vector<RejectedBranch> rejected;
  const auto kept = modelBranches(pts, index, trunk, region, config, &rejected);
  ASSERT_EQ(kept.size(), 1u);
  EXPECT_GT(kept[0].cylinder.axis.dot(OUT), std::cos(5.0 * M_PI / 180));
  EXPECT_NEAR(kept[0].attachment.z(), 0.9, 0.03);
  EXPECT_FALSE(kept[0].reaches_surface);
  EXPECT_EQ(countReason(rejected, BranchRejection::TOO_SHORT), 1);  // the piece at the trunk

  config.branches.keep_cut_off = false;
  rejected.clear();
  EXPECT_TRUE(modelBranches(pts, index, trunk, region, config, &rejected).empty());
  EXPECT_GE(countReason(rejected, BranchRejection::NOT_AT_THE_SURFACE),
            1);  // and its halves, retried
}

TEST(BranchCutOff, ATipWithAirBetweenItAndTheTrunkIsNot) {
  Points pts;
  addCylinder(pts, {0, 0, 0}, {0, 0, 1}, 0.03, 1.5);
  const std::size_t trunk_points = pts.size();
  addBranchPart(pts, 0.12, 0.40);  // aimed at the trunk, but nothing nearer than 12 cm
  auto [region, config, trunk] = buildTrunk(pts, trunk_points);
  std::vector<RejectedBranch> rejected;
  EXPECT_TRUE(modelBranches(pts, PointIndex(pts), trunk, region, config, &rejected).empty());
  EXPECT_GE(countReason(rejected, BranchRejection::NOT_AT_THE_SURFACE),
            1);  // and its halves, retried
}

}  // namespace
}  // namespace modeling
}  // namespace dormant_tree_modeling
