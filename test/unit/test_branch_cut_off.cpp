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
using test::addIsotropicNoise;
using test::buildTrunk;
using test::lineAngleDeg;

const Eigen::Vector3d OUT = Eigen::Vector3d(1, 0, 0.1).normalized();
constexpr double BRANCH_RADIUS = 0.01;
// The crossing scene's two primaries: one level along x, one 9 degrees around from it rising
// at 40 degrees.
const Eigen::Vector3d LEVEL(1, 0, 0);
const Eigen::Vector3d AROUND(std::cos(-9.0 * M_PI / 180), std::sin(-9.0 * M_PI / 180), 0);
const Eigen::Vector3d RISING =
    std::cos(40.0 * M_PI / 180) * AROUND + std::sin(40.0 * M_PI / 180) * Eigen::Vector3d::UnitZ();

// Where the level branches leave the 3 cm trunk.
const Eigen::Vector3d BRANCH_BASE(0.03, 0, 0.9);

/// A level branch leaving the 3 cm trunk at z 0.9 m: its returns from `from` to `to` metres
/// off the trunk surface.
void addBranchPart(Points& pts, double from, double to, double radius = BRANCH_RADIUS) {
  addCylinder(pts, BRANCH_BASE + from * OUT, OUT, radius, to - from);
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

/// A level primary leaving the 3 cm trunk at z 1.12 m, and a thicker one leaving it 14 cm lower
/// and rising: it passes 2.6 cm beside the first 17 cm out, and its extraction cuts the first
/// in two. Every point moved by isotropic noise of `sigma_m`.
Points crossingScene(double sigma_m, unsigned seed, std::size_t* trunk_points) {
  Points pts;
  addCylinder(pts, {0, 0, 0}, {0, 0, 1}, 0.03, 1.5);
  *trunk_points = pts.size();
  addCylinder(pts, {0.03, 0, 1.12}, LEVEL, 0.0066, 0.6);
  addCylinder(pts, 0.03 * AROUND + Eigen::Vector3d(0, 0, 0.98), RISING, 0.009, 0.6);
  addIsotropicNoise(pts, sigma_m, seed);
  return pts;
}

TEST(BranchCutOff, ABranchCutByACrossingOneIsJudgedAlongItsWholeOuterPiece) {
  // Over 12 seeded scenes at 6 and 12 mm noise. The outer piece's near part keeps returns of
  // the crossing primary at its inner end, and its fit turns towards it. Judged along that
  // fit, the level primary was found (within 10 degrees) in 3 scenes; judged along the line
  // through the whole piece, in 7. Of the other five, four keep a fit turned by 13-28 degrees
  // and one misses it.
  int level_found = 0;
  for (const double sigma : {0.006, 0.012})
    for (const unsigned seed : {1u, 2u, 3u, 4u, 5u, 6u}) {
      std::size_t trunk_points = 0;
      const Points pts = crossingScene(sigma, seed, &trunk_points);
      auto [region, config, trunk] = buildTrunk(pts, trunk_points);
      config.noise.sigma_m = sigma;
      const auto kept = modelBranches(pts, PointIndex(pts), trunk, region, config, nullptr);
      SCOPED_TRACE(testing::Message() << "noise " << sigma << " seed " << seed);
      ASSERT_LE(kept.size(), 2u);
      int level = 0, rising = 0;
      for (const auto& k : kept) {
        level += lineAngleDeg(k.cylinder.axis, LEVEL) < 10.0;
        rising += lineAngleDeg(k.cylinder.axis, RISING) < 10.0;
      }
      EXPECT_EQ(rising, 1);
      level_found += level;
    }
  EXPECT_GE(level_found, 7);
}

/// A level primary (6.6 mm) leaving the 3 cm trunk at z 0.9 m, whose outer 28 cm, from 14 cm
/// off the surface, turn 15 degrees around the vertical: the line through that piece misses the
/// way its near end takes back to the trunk by 2-4 cm, as a crossing branch's leftover returns
/// turn a piece's line on a tree. Its returns from 7 to 14 cm off the surface are flagged in
/// *taken (what the crossing branch's extraction takes from the candidates; the returns stay in
/// the cloud). Every point moved by isotropic noise of 2 mm.
Points turnedPieceScene(unsigned seed, std::size_t* trunk_points, std::vector<char>* taken,
                        Eigen::Vector3d* outer_axis) {
  Points pts;
  addCylinder(pts, {0, 0, 0}, {0, 0, 1}, 0.03, 1.5);
  *trunk_points = pts.size();
  addBranchPart(pts, 0.0, 0.14, 0.0066);
  const std::size_t base_end = pts.size();
  *outer_axis = Eigen::AngleAxisd(15.0 * M_PI / 180, Eigen::Vector3d::UnitZ()) * OUT;
  addCylinder(pts, BRANCH_BASE + 0.14 * OUT, *outer_axis, 0.0066, 0.28);
  addIsotropicNoise(pts, 0.002, seed);
  taken->assign(pts.size(), 0);
  for (std::size_t k = *trunk_points; k < base_end; ++k)
    (*taken)[k] = (pts[k] - BRANCH_BASE).dot(OUT) > 0.07;
  return pts;
}

TEST(BranchCutOff, ACutOffPieceIsJudgedAlongTheWayFromItsNearEndToTheTrunk) {
  // Four seeds. Walked back along the piece's own axis, the walk leaves the branch's returns
  // near the trunk and the piece was turned down in all four.
  for (const unsigned seed : {1u, 2u, 3u, 4u}) {
    std::size_t trunk_points = 0;
    std::vector<char> taken;
    Eigen::Vector3d outer_axis;
    const Points pts = turnedPieceScene(seed, &trunk_points, &taken, &outer_axis);
    auto [region, config, trunk] = buildTrunk(pts, trunk_points);
    const auto kept =
        modelBranches(pts, PointIndex(pts), trunk, region, config, nullptr, {}, taken);
    SCOPED_TRACE(testing::Message() << "seed " << seed);
    ASSERT_EQ(kept.size(), 1u);
    EXPECT_LT(lineAngleDeg(kept[0].cylinder.axis, outer_axis), 5.0);
    EXPECT_FALSE(kept[0].reaches_surface);
  }
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
