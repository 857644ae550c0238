// Branch axes from one side: each side's estimate of a branch axis lands on the true axis, so
// the front and the back station can be pulled together along the rays, which nearest-point
// pairs of the two opposite halves cannot do.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/registration/branch_axes.h"
#include "dormant_tree_modeling/registration/icp.h"
#include "dormant_tree_modeling/registration/multi_view.h"

namespace dormant_tree_modeling {
namespace registration {
namespace {

struct Stick {
  Eigen::Vector3d centre, axis;
  double radius, length;
};

// What a sensor at `sensor` sees of the sticks: the facing half of each, sampled evenly across
// the silhouette (as beams fan across it), with Gaussian range noise along each ray.
struct HalfView {
  Points points, view_dirs;
  std::vector<double> ranges;
};

HalfView seeHalves(const std::vector<Stick>& sticks, const Eigen::Vector3d& sensor, double sigma,
                   unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  HalfView v;
  for (const auto& s : sticks) {
    const Eigen::Vector3d a = s.axis.normalized();
    const Eigen::Vector3d to_sensor = sensor - s.centre;
    const Eigen::Vector3d depth = (to_sensor - to_sensor.dot(a) * a).normalized();
    const Eigen::Vector3d across = a.cross(depth);
    for (double t = -s.length / 2; t <= s.length / 2; t += 0.004) {
      for (double x = -s.radius + 0.0015; x < s.radius; x += 0.003) {
        const Eigen::Vector3d surface =
            s.centre + t * a + x * across + std::sqrt(s.radius * s.radius - x * x) * depth;
        const Eigen::Vector3d ray = (sensor - surface).normalized();
        const Eigen::Vector3d p = surface - noise(rng) * ray;
        v.points.push_back(p);
        v.view_dirs.push_back(ray);
        v.ranges.push_back((sensor - p).norm());
      }
    }
  }
  return v;
}

// Ideal beams (no footprint, the default): the silhouette is the branch's width.
AxisConfig idealBeams() {
  return AxisConfig{};
}

// Distance from p to the stick's axis line.
double offAxis(const Stick& s, const Eigen::Vector3d& p) {
  const Eigen::Vector3d a = s.axis.normalized();
  const Eigen::Vector3d d = p - s.centre;
  return (d - d.dot(a) * a).norm();
}

const std::vector<Stick> STICKS = {{{0.0, 0.0, 1.5}, {1, 0, 0}, 0.02, 0.5},
                                   {{0.3, 0.1, 1.9}, {1, 0.3, 1.2}, 0.015, 0.5},
                                   {{-0.4, -0.1, 1.2}, {1, 0.2, -0.6}, 0.025, 0.5},
                                   {{0.1, 0.05, 2.4}, {0.2, 0.1, 1}, 0.012, 0.5},
                                   {{-0.2, 0.0, 2.1}, {1, -0.3, 0.5}, 0.018, 0.5},
                                   {{0.5, -0.05, 1.1}, {-0.5, 0.2, 1}, 0.02, 0.5}};

TEST(BranchAxes, FindTheAxisFromEitherSide) {
  const Stick stick = STICKS.front();
  const Points centres = {{-0.1, 0.0, 1.5}, {0.0, 0.0, 1.5}, {0.1, 0.0, 1.5}};
  for (const double side : {-2.0, 2.0}) {
    const HalfView v = seeHalves({stick}, {0.0, side, 1.5}, 0.0, 1);
    const AxisSamples a = estimateAxes(v.points, v.view_dirs, v.ranges, centres, idealBeams());
    ASSERT_EQ(a.size(), centres.size()) << "side " << side;
    for (std::size_t i = 0; i < a.size(); ++i) {
      EXPECT_LT(offAxis(stick, a.points[i]), 0.001) << "side " << side;
      EXPECT_NEAR(a.radii[i], stick.radius, 0.002);
      EXPECT_GT(std::abs(a.directions[i].dot(stick.axis)), 0.999);
      EXPECT_GT(a.view_dirs[i].y() * side, 0.99);  // towards the sensor
    }
  }
}

TEST(BranchAxes, BranchesThickerThanTheCalibratedRodsGiveNoSamples) {
  // A sample is centred on one of the station's points, on the visible surface: from near one
  // edge of a 35 mm branch the far edge lies beyond the 10 cm patch, and the cut silhouette
  // reads thin with its axis too near the sensor. An ideal beam's calibration whose rods reach
  // 20 mm keeps silhouettes to 46 mm wide (COVERAGE_RADIUS_SLACK): the thick branch gives
  // none, a 15 mm one still gives its axis.
  const Stick thick{{0.0, 0.0, 1.5}, {1, 0, 0}, 0.035, 0.5};
  const Stick thin{{0.0, 0.0, 1.5}, {1, 0, 0}, 0.015, 0.5};
  auto surfaceCentres = [](const Stick& s) {
    Points centres;
    for (const double x : {-0.8, -0.5, 0.5, 0.8})
      centres.emplace_back(0.0, -std::sqrt(1.0 - x * x) * s.radius, 1.5 + x * s.radius);
    return centres;
  };
  const HalfView v = seeHalves({thick}, {0.0, -2.0, 1.5}, 0.0, 1);
  const AxisSamples uncovered =
      estimateAxes(v.points, v.view_dirs, v.ranges, surfaceCentres(thick), idealBeams());
  double worst = 0.0;
  for (std::size_t i = 0; i < uncovered.size(); ++i)
    worst = std::max(worst, offAxis(thick, uncovered.points[i]));
  EXPECT_GT(worst, 0.004) << "without a radius limit the cut silhouettes sit off the axis";

  modeling::SensorCalibration calibration;
  calibration.name = "ideal rig";
  calibration.silhouette.measured = true;
  calibration.coverage.branch_radius_min_m = 0.002;
  calibration.coverage.branch_radius_max_m = 0.02;
  RegistrationConfig config;
  ASSERT_TRUE(applySensorCalibration(calibration, config));
  EXPECT_EQ(
      estimateAxes(v.points, v.view_dirs, v.ranges, surfaceCentres(thick), config.axes).size(), 0u);
  const HalfView w = seeHalves({thin}, {0.0, -2.0, 1.5}, 0.0, 1);
  const AxisSamples kept =
      estimateAxes(w.points, w.view_dirs, w.ranges, surfaceCentres(thin), config.axes);
  ASSERT_EQ(kept.size(), 4u);
  for (std::size_t i = 0; i < kept.size(); ++i) {
    EXPECT_NEAR(kept.radii[i], thin.radius, 0.002);
    EXPECT_LT(offAxis(thin, kept.points[i]), 0.002);
  }
}

TEST(BranchAxes, StayOnTheAxisUnderRangeNoise) {
  // 6 mm range noise moves single points by a third of the radius; the median holds.
  double worst = 0, mean_radius = 0;
  int n = 0;
  for (const double side : {-2.0, 2.0}) {
    const HalfView v = seeHalves(STICKS, {0.0, side, 1.5}, 0.006, side > 0 ? 2 : 3);
    Points centres;
    for (const auto& s : STICKS)
      centres.push_back(s.centre);
    const AxisSamples a = estimateAxes(v.points, v.view_dirs, v.ranges, centres, idealBeams());
    ASSERT_GE(a.size(), STICKS.size() - 1);
    for (std::size_t i = 0; i < a.size(); ++i) {
      double best = INFINITY;
      for (const auto& s : STICKS)
        best = std::min(best, offAxis(s, a.points[i]));
      worst = std::max(worst, best);
      mean_radius += a.radii[i];
      ++n;
    }
  }
  std::printf("[ INFO ] %d samples, worst %.2f mm off the axis, mean radius %.1f mm\n", n,
              worst * 1000, mean_radius / n * 1000);
  EXPECT_LT(worst, 0.003);
}

TEST(BranchAxes, SkipPlanesTrunksAndMixedSides) {
  // A wall: no stick.
  HalfView wall;
  for (double x = -0.1; x <= 0.1; x += 0.004) {
    for (double z = 1.4; z <= 1.6; z += 0.004) {
      wall.points.emplace_back(x, 0.0, z);
      wall.view_dirs.push_back(-Eigen::Vector3d::UnitY());
      wall.ranges.push_back(2.0);
    }
  }
  const Points centre = {{0.0, 0.0, 1.5}};
  EXPECT_EQ(estimateAxes(wall.points, wall.view_dirs, wall.ranges, centre, idealBeams()).size(),
            0u);
  // A trunk (8 cm radius) is thicker than any branch the samples are for.
  const HalfView trunk = seeHalves({{{0, 0, 1.5}, {0, 0, 1}, 0.08, 0.4}}, {0, -2, 1.5}, 0, 1);
  EXPECT_EQ(
      estimateAxes(trunk.points, trunk.view_dirs, trunk.ranges, {{0, -0.08, 1.5}}, idealBeams())
          .size(),
      0u);
  // Both halves of one branch in one patch: not one side's view.
  HalfView both = seeHalves({STICKS.front()}, {0, -2, 1.5}, 0, 1);
  const HalfView back = seeHalves({STICKS.front()}, {0, 2, 1.5}, 0, 1);
  both.points.insert(both.points.end(), back.points.begin(), back.points.end());
  both.view_dirs.insert(both.view_dirs.end(), back.view_dirs.begin(), back.view_dirs.end());
  both.ranges.insert(both.ranges.end(), back.ranges.begin(), back.ranges.end());
  EXPECT_EQ(
      estimateAxes(both.points, both.view_dirs, both.ranges, {{0, 0, 1.5}}, idealBeams()).size(),
      0u);
  // The beam footprint widens the silhouette: beams half on the branch report its edge. Taken
  // off, the radius is the branch's (a wider patch holds the widened silhouette whole).
  AxisConfig beams;  // a calibrated growth: 2 mm + 8 mm per metre, 18 mm at 2 m
  beams.patch_m = 0.1;
  beams.silhouette_growth_m = 0.002;
  beams.silhouette_growth_per_m = 0.008;
  HalfView wide = seeHalves({STICKS.front()}, {0, -2, 1.5}, 0, 1);
  const double grow = 0.5 * (0.002 + 0.008 * 2.0);
  for (const double side : {1.0, -1.0}) {
    for (double z = 0.02 + 0.0015; z <= 0.02 + grow; z += 0.003) {
      for (double x = -0.25; x <= 0.25; x += 0.004) {
        wide.points.emplace_back(x, 0.0, 1.5 + side * z);
        wide.view_dirs.push_back(-Eigen::Vector3d::UnitY());
        wide.ranges.push_back(2.0);
      }
    }
  }
  const AxisSamples w =
      estimateAxes(wide.points, wide.view_dirs, wide.ranges, {{0.0, -0.01, 1.5}}, beams);
  ASSERT_EQ(w.size(), 1u);
  EXPECT_NEAR(w.radii[0], 0.02, 0.0015);
  EXPECT_LT(offAxis(STICKS.front(), w.points[0]), 0.0015);
}

// A wide beam: every silhouette gains wings at the branch's edge range until it is
// 0.4 x the diameter + 30 mm wide, so a 10 mm and a 40 mm branch look 34 and 46 mm wide.
HalfView wideBeamHalf(const Stick& s, const Eigen::Vector3d& sensor) {
  constexpr double GAIN = 0.4, MARGIN = 0.03;
  HalfView v = seeHalves({s}, sensor, 0, 1);
  const double half_width = 0.5 * (GAIN * 2 * s.radius + MARGIN);
  const Eigen::Vector3d a = s.axis.normalized();
  const Eigen::Vector3d to_sensor = sensor - s.centre;
  const Eigen::Vector3d depth = (to_sensor - to_sensor.dot(a) * a).normalized();
  const Eigen::Vector3d across = a.cross(depth);
  for (const double side : {1.0, -1.0}) {
    for (double x = s.radius + 0.0015; x <= half_width; x += 0.003) {
      for (double t = -s.length / 2; t <= s.length / 2; t += 0.004) {
        const Eigen::Vector3d p = s.centre + t * a + side * x * across;
        v.points.push_back(p);
        v.view_dirs.push_back((sensor - p).normalized());
        v.ranges.push_back((sensor - p).norm());
      }
    }
  }
  return v;
}

TEST(BranchAxes, AWideBeamsRadiusDividesByTheDiameterGain) {
  AxisConfig wide;  // the calibration of that beam: gain 0.4, 30 mm
  wide.silhouette_growth_m = 0.03;
  wide.silhouette_diameter_gain = 0.4;
  AxisConfig margin_only = wide;  // the same beam taken as a margin fitted at 25 mm across
  margin_only.silhouette_diameter_gain = 1.0;
  margin_only.silhouette_growth_m = 0.03 - 0.6 * 0.025;
  for (const double radius : {0.005, 0.02}) {
    const Stick stick{{0.0, 0.0, 1.5}, {1, 0, 0}, radius, 0.5};
    const HalfView v = wideBeamHalf(stick, {0.0, -2.0, 1.5});
    const AxisSamples a = estimateAxes(v.points, v.view_dirs, v.ranges, {stick.centre}, wide);
    ASSERT_EQ(a.size(), 1u) << radius;
    EXPECT_NEAR(a.radii[0], radius, 0.001);
    EXPECT_LT(offAxis(stick, a.points[0]), 0.0015);
    // With the gain taken as 1 the thin branch reads 4.5 mm thick too, the thick one 4.5 mm
    // thin, and the axes sit that far off along the rays.
    const AxisSamples m =
        estimateAxes(v.points, v.view_dirs, v.ranges, {stick.centre}, margin_only);
    ASSERT_EQ(m.size(), 1u) << radius;
    EXPECT_GT(std::abs(m.radii[0] - radius), 0.004);
  }
  AxisConfig bad = wide;
  bad.silhouette_diameter_gain = 0.05;
  EXPECT_THROW(bad.validate(), Error);
}

TEST(BranchAxes, RejectBadInput) {
  AxisConfig bad;
  bad.silhouette_growth_per_m = 0.5;
  EXPECT_THROW(bad.validate(), Error);
  bad = AxisConfig{};
  bad.max_radius_m = 0.001;
  EXPECT_THROW(bad.validate(), Error);
  EXPECT_THROW(estimateAxes(Points(20), Points(19), std::vector<double>(20), {}, AxisConfig{}),
               Error);
  EXPECT_EQ(estimateAxes({}, {}, {}, {{0, 0, 0}}, AxisConfig{}).size(), 0u);
}

// A back station that sits 9 mm too close to the front one (along the rays), with only the
// opposite halves of branches in common: axis pairs pull it back.
TEST(BranchAxes, PullABackStationBackAlongTheRays) {
  const Eigen::Vector3d front(0, -2, 1.8), back(0, 2, 1.8);
  const HalfView f = seeHalves(STICKS, front, 0.004, 4), b = seeHalves(STICKS, back, 0.004, 5);
  IcpConfig icp;
  auto pyramid = [&](const HalfView& v) {
    Pyramid p = makePyramid(v.points, v.view_dirs, icp.voxels_m, icp.normal_neighbors);
    p.axes = estimateAxes(v.points, v.view_dirs, v.ranges, p.levels[1].points, idealBeams());
    return p;
  };
  const Pyramid target = pyramid(f), source = pyramid(b);
  ASSERT_GT(target.axes.size(), 20u);
  ASSERT_GT(source.axes.size(), 20u);
  Eigen::Isometry3d guess = Eigen::Isometry3d::Identity();
  guess.translation() = Eigen::Vector3d(0.003, -0.009, 0.002);
  const int finest = static_cast<int>(icp.voxels_m.size()) - 1;
  const IcpResult with_axes = alignPyramids(source, target, guess, icp, finest);
  icp.axis_pairs = false;
  const IcpResult ray_only = alignPyramids(source, target, guess, icp, finest);
  const Eigen::Vector3d left = with_axes.transform.translation();
  std::printf(
      "[ INFO ] back station 9 mm too close: %.2f mm left along the rays with axis pairs "
      "(%.2f mm in all), %.2f mm with point-to-ray pairs\n",
      std::abs(left.y()) * 1000, left.norm() * 1000,
      std::abs(ray_only.transform.translation().y()) * 1000);
  // Six sticks under 4 mm noise pin the pose to a few millimetres (a tree has hundreds).
  EXPECT_LT(std::abs(left.y()), 0.003);
  EXPECT_LT(left.norm(), 0.004);
}

}  // namespace
}  // namespace registration
}  // namespace dormant_tree_modeling
