// The scan assembler's core: θ from stamped stage positions, the range image of a sweep,
// Eq. 1, spherical-to-Cartesian, and isolating the target tree in a simulated orchard view.
#include <gtest/gtest.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cmath>
#include <set>
#include <tuple>

#include "dormant_tree_modeling/acquisition/sweep_assembler.h"
#include "dormant_tree_modeling/acquisition/target_isolation.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/simulation/dataset.h"
#include "dormant_tree_modeling/simulation/orchard_generator.h"
#include "dormant_tree_modeling/simulation/ray_caster.h"
#include "dormant_tree_modeling/simulation/view_simulator.h"

namespace dormant_tree_modeling {
namespace acquisition {
namespace {

TEST(StagePositionHistory, InterpolatesAndRefusesGaps) {
  StagePositionHistory h(0.05);
  for (int i = 0; i <= 10; ++i)
    h.add(i * 0.02, 0.1 * i);
  h.add(0.1, 99.0);  // out of order: ignored
  EXPECT_NEAR(*h.at(0.03), 0.15, 1e-12);
  EXPECT_NEAR(*h.at(0.2), 1.0, 1e-12);
  EXPECT_NEAR(*h.at(0.24), 1.0, 1e-12);  // held within max_gap past the end
  EXPECT_FALSE(h.at(0.26));
  EXPECT_FALSE(h.at(-0.06));
  h.add(0.5, 2.0);  // a 0.3 s hole in the feedback
  EXPECT_FALSE(h.at(0.4));
}

TEST(AssembleRangeImage, ContinuousSweepGivesEachBeamItsTheta) {
  // The stage turns at 11.25 deg/s (0.45 deg per 40 ms line) while lines of 5 beams come.
  const double omega = 11.25 * M_PI / 180.0;
  StagePositionHistory h;
  for (int i = 0; i <= 500; ++i)
    h.add(i * 0.02, -M_PI / 4 + omega * i * 0.02);
  std::vector<SweepLine> lines;
  for (int k = 0; k < 200; ++k) {
    SweepLine l;
    l.stamp = 0.01 + 0.04 * k;
    l.time_increment = 0.001;
    l.phi0 = 0.0;
    l.phi_step = M_PI / 4;
    l.ranges = {1.0f, 2.0f, 0.0f, std::nanf(""), 3.0f};
    lines.push_back(l);
  }
  // Lines arrive out of order: rows come out sorted by θ.
  std::swap(lines[3], lines[7]);
  std::size_t dropped = 0;
  const RangeImage img = assembleRangeImage(lines, h, -M_PI / 4, M_PI / 4, &dropped);
  ASSERT_EQ(img.rows, 200);
  EXPECT_EQ(dropped, 0u);
  EXPECT_EQ(img.cols, 5);
  EXPECT_NEAR(img.theta(0), -M_PI / 4 + omega * 0.01, 1e-9);
  EXPECT_NEAR(img.theta(7, 4), -M_PI / 4 + omega * (0.01 + 0.28 + 0.004), 1e-9);
  EXPECT_EQ(img.at(0, 3), 0.0f);  // NaN -> no return
  for (int i = 1; i < img.rows; ++i)
    EXPECT_GT(img.theta(i), img.theta(i - 1));
  // On the nominal grid of 0.45 deg: the same 200 rows, one per step.
  std::size_t missing = 1;
  const RangeImage grid =
      assembleRangeImage(lines, h, -M_PI / 4, M_PI / 4, nullptr, 0.45 * M_PI / 180, &missing);
  EXPECT_EQ(grid.rows, 200);
  EXPECT_EQ(missing, 0u);
  EXPECT_NEAR(grid.theta(10), img.theta(10), 1e-12);
  // Half the sweep's lines lost: their rows stay empty and are counted.
  std::vector<SweepLine> half(lines.begin(), lines.begin() + 100);
  const RangeImage holes =
      assembleRangeImage(half, h, -M_PI / 4, M_PI / 4, nullptr, 0.45 * M_PI / 180, &missing);
  EXPECT_EQ(holes.rows, 200);
  EXPECT_EQ(missing, 100u);
  EXPECT_EQ(holes.at(150, 0), 0.0f);
  // Without stage feedback for a line it is dropped, not guessed.
  StagePositionHistory partial;
  for (int i = 0; i <= 100; ++i)
    partial.add(i * 0.02, omega * i * 0.02);
  assembleRangeImage(lines, partial, -1.0, 1.0, &dropped);
  EXPECT_EQ(dropped, 147u);  // covered: stamps up to 2.0 s + 0.1 s of hold, 53 lines
  lines[5].ranges.pop_back();
  EXPECT_THROW(assembleRangeImage(lines, h, -1.0, 1.0), Error);
}

TEST(RangeImage, MiddleStampSkipsRowsWithoutALine) {
  RangeImage img;
  EXPECT_FALSE(img.middleStamp().has_value());
  img.row_stamp = {10.0, 10.1, 10.2, 10.3, 10.4};
  EXPECT_DOUBLE_EQ(*img.middleStamp(), 10.2);
  // A missing middle line (stamp 0) would stamp the view at time 0, "the latest" to tf.
  img.row_stamp = {10.0, 0.0, 0.0, 10.3, 10.4};
  EXPECT_DOUBLE_EQ(*img.middleStamp(), 10.3);
  img.row_stamp = {10.0, 10.1, 0.0, 10.3, 10.4};
  EXPECT_DOUBLE_EQ(*img.middleStamp(), 10.1);  // equally near: the earlier
  img.row_stamp = {0.0, 0.0, 0.0, 0.0};
  EXPECT_FALSE(img.middleStamp().has_value());
}

TEST(FloatingPixels, Equation1OnKnownImages) {
  RangeImage img;
  img.resize(4, 5);
  // A flat surface at 2 m with an isolated return, a depth edge with a mixed pixel between
  // the tree (1 m) and the background (3 m), and a lone return in empty space.
  const float rows[4][5] = {{1.0f, 1.0f, 2.0f, 3.0f, 3.0f},
                            {1.0f, 1.0f, 1.6f, 3.0f, 3.0f},
                            {1.0f, 1.0f, 1.02f, 3.0f, 3.0f},
                            {0.0f, 0.0f, 0.0f, 0.0f, 5.0f}};
  for (int i = 0; i < 4; ++i)
    for (int j = 0; j < 5; ++j)
      img.at(i, j) = rows[i][j];
  EXPECT_EQ(removeFloatingPixels(img, 0.1), 3u);
  EXPECT_EQ(img.at(0, 2), 0.0f);  // mixed pixels: 0.4 m and more from every neighbour
  EXPECT_EQ(img.at(1, 2), 0.0f);
  EXPECT_EQ(img.at(2, 2), 1.02f);  // on the tree, 2 cm from its neighbours
  EXPECT_EQ(img.at(3, 4), 0.0f);   // 2 m behind the background, alone
  EXPECT_EQ(img.at(0, 3), 3.0f);   // the background stays
  EXPECT_EQ(img.at(2, 0), 1.0f);
  RangeImage lone;
  lone.resize(3, 3);
  lone.at(1, 1) = 4.0f;
  EXPECT_EQ(removeFloatingPixels(lone, 0.1), 1u);
}

TEST(SphericalToCartesian, KnownPoints) {
  double x, y, z;
  sphericalToCartesian(2.0, 0.0, M_PI / 2, x, y, z);  // horizontal, straight ahead
  EXPECT_NEAR(x, 2.0, 1e-12);
  EXPECT_NEAR(y, 0.0, 1e-12);
  EXPECT_NEAR(z, 0.0, 1e-12);
  sphericalToCartesian(2.0, 0.3, 0.0, x, y, z);  // straight down whatever θ
  EXPECT_NEAR(z, -2.0, 1e-12);
  EXPECT_NEAR(std::hypot(x, y), 0.0, 1e-12);
  sphericalToCartesian(1.0, M_PI / 2, M_PI / 2, x, y, z);  // turned to the left
  EXPECT_NEAR(y, 1.0, 1e-12);
  sphericalToCartesian(1.0, 0.0, M_PI, x, y, z);  // straight up
  EXPECT_NEAR(z, 1.0, 1e-12);
}

struct LabelledView {
  Cloud cloud;
  std::set<std::tuple<float, float, float>> target;  // points on the target tree
};

// One simulated view of an orchard, in the stage frame, with the target tree's points known.
LabelledView labelledView(const simulation::Orchard& orchard, const Eigen::Isometry3d& platform,
                          std::uint64_t seed) {
  const simulation::RayCaster caster(orchard.scene);
  simulation::Lms111Config sensor;
  sensor.angular_resolution_deg = 0.5;
  sensor.scan_frequency_hz = 50.0;
  const simulation::Lms111Model model(caster, sensor);
  const geometry::StageGeometry geometry;
  ViewPlanConfig sweep;
  sweep.theta_step_deg = 0.9;
  const simulation::SimulatedView view = simulation::simulateView(
      model, geometry::stagePose(platform, geometry, 0.0), geometry, sweep, seed, 0, 2);
  LabelledView out;
  for (int i = 0; i < view.image.rows; ++i) {
    for (int j = 0; j < view.image.cols; ++j) {
      const float rho = view.image.at(i, j);
      if (!(rho > 0.0f) || view.image.phi(j) >= M_PI)
        continue;
      double x, y, z;
      sphericalToCartesian(rho, view.image.theta(i), view.image.phi(j), x, y, z);
      const pcl::PointXYZ p(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z));
      out.cloud.push_back(p);
      const auto& label = view.labels[static_cast<std::size_t>(i) * view.image.cols + j];
      if (label.object == 0 && label.part <= simulation::Part::MINOR)
        out.target.insert({p.x, p.y, p.z});
    }
  }
  return out;
}

std::pair<double, double> recallPrecision(const LabelledView& v, const IsolationResult& r) {
  std::size_t kept_target = 0;
  for (const auto& p : *r.cloud)
    kept_target += v.target.count({p.x, p.y, p.z});
  return {static_cast<double>(kept_target) / v.target.size(),
          static_cast<double>(kept_target) / r.cloud->size()};
}

TEST(TargetIsolation, HighViewsBesideTheTreeWithTheOperatorsError) {
  // From 4 m, half a metre along the row from the tree: the trunk's base is hidden by the
  // branches above it, and a post and a neighbour may stand nearer the platform's axis. The
  // platform stands where an operator put it (up to 0.2 m / 8 deg off the plan); the hint
  // is the plan's.
  Rng rng(11);
  for (std::uint64_t seed : {1, 2}) {
    simulation::OrchardConfig oc;
    const simulation::Orchard orchard = simulation::generateOrchard(oc, seed);
    for (double x : {-0.5, 0.5}) {
      const Eigen::Isometry3d plan = geometry::platformPose(x, -1.5, 4.0, M_PI / 2);
      const Eigen::Isometry3d platform = plan * simulation::randomPlatformError(rng, 0.2, 8.0);
      const LabelledView v = labelledView(orchard, platform, seed);
      const Eigen::Vector2d hint = (plan.inverse() * Eigen::Vector3d::Zero()).head<2>();
      const Eigen::Vector3d truth = platform.inverse() * Eigen::Vector3d::Zero();
      const IsolationResult r = isolateTarget(v.cloud, Eigen::Vector3d::Zero(),
                                              Eigen::Vector3d::UnitX(), hint, {}, truth.z());
      const auto [recall, precision] = recallPrecision(v, r);
      std::printf(
          "[ INFO ] seed %d, x %+.1f: ground %s %.2f, trunk (%.2f, %.2f) truth (%.2f, "
          "%.2f) hint (%.2f, %.2f), recall %.3f, precision %.3f\n",
          static_cast<int>(seed), x, r.ground_from_plan ? "from the plan" : "seen", r.ground_z,
          r.trunk.x(), r.trunk.y(), truth.x(), truth.y(), hint.x(), hint.y(), recall, precision);
      EXPECT_LT((r.trunk - truth.head<2>()).norm(), 0.1) << seed << " " << x;
      EXPECT_GT(recall, 0.8) << seed << " " << x;
      EXPECT_GT(precision, 0.6) << seed << " " << x;
    }
  }
}

TEST(TargetIsolation, TakesThePlansGroundWhenNoneIsSeen) {
  // No ground in the scene (a view over tall grass or snow that returns nothing): the trunk
  // band is placed from the plan's ground level, so posts and neighbours are still cut out.
  simulation::OrchardConfig oc;
  oc.ground = false;
  const simulation::Orchard orchard = simulation::generateOrchard(oc, 1);
  const LabelledView v = labelledView(orchard, geometry::platformPose(0.0, -1.5, 4.0, M_PI / 2), 1);
  const IsolationResult without =
      isolateTarget(v.cloud, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(), {1.5, 0.0}, {});
  const IsolationResult with = isolateTarget(v.cloud, Eigen::Vector3d::Zero(),
                                             Eigen::Vector3d::UnitX(), {1.5, 0.0}, {}, -4.0);
  EXPECT_FALSE(without.ground_found);
  ASSERT_TRUE(with.ground_found);
  EXPECT_TRUE(with.ground_from_plan);
  EXPECT_DOUBLE_EQ(with.ground_z, -4.0);
  EXPECT_NEAR(with.trunk.x(), 1.5, 0.1);
  EXPECT_NEAR(with.trunk.y(), 0.0, 0.1);
  const auto [recall, precision] = recallPrecision(v, with);
  const auto [recall0, precision0] = recallPrecision(v, without);
  std::printf(
      "[ INFO ] no ground: recall %.3f, precision %.3f with the plan's ground; %.3f, %.3f "
      "without\n",
      recall, precision, recall0, precision0);
  EXPECT_GT(recall, 0.8);
  EXPECT_GT(precision, 0.75);
}

TEST(TargetIsolation, CutsTheTargetTreeOutOfOrchardViews) {
  // One front view per preset, at trunk height, 1.5 m in front of the tree: neighbours in the
  // row 0.9-1.2 m to the sides, a trellis post, wires, the next rows, the ground.
  const std::pair<const char*, std::uint64_t> trees[] = {
      {"young_tall_spindle", 4}, {"mature_tall_spindle", 5}, {"central_leader", 6}};
  for (const auto& [preset, seed] : trees) {
    simulation::OrchardConfig oc;
    oc.preset = preset;
    const simulation::Orchard orchard = simulation::generateOrchard(oc, seed);
    const LabelledView v =
        labelledView(orchard, geometry::platformPose(0.0, -1.5, 1.5, M_PI / 2), seed);
    const IsolationResult r =
        isolateTarget(v.cloud, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(),
                      Eigen::Vector2d(1.5, 0.0), IsolationConfig{});
    EXPECT_TRUE(r.ground_found) << preset;
    EXPECT_NEAR(r.ground_z, -1.5, 0.05) << preset;  // the platform frame is at laser height
    EXPECT_NEAR(r.trunk.x(), 1.5, 0.1) << preset;   // the trunk, 1.5 m ahead on the axis
    EXPECT_NEAR(r.trunk.y(), 0.0, 0.1) << preset;
    const auto [recall, precision] = recallPrecision(v, r);
    std::printf("[ INFO ] %s: %zu points, %zu on the tree; kept %zu: recall %.3f, precision %.3f\n",
                preset, v.cloud.size(), v.target.size(), r.cloud->size(), recall, precision);
    // A cylinder of crop_radius loses the outer tips of wide trees (central leader: 0.84).
    EXPECT_GT(recall, 0.8) << preset;
    EXPECT_GT(precision, 0.75) << preset;
  }
  Cloud empty;
  EXPECT_THROW(isolateTarget(empty, Eigen::Vector3d::Zero(), Eigen::Vector3d::UnitX(),
                             Eigen::Vector2d(1.5, 0.0), {}),
               Error);
}

}  // namespace
}  // namespace acquisition
}  // namespace dormant_tree_modeling
