#include <gtest/gtest.h>

#include <cmath>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/geometry/stage_kinematics.h"
#include "dormant_tree_modeling/simulation/lms111_model.h"
#include "dormant_tree_modeling/simulation/view_simulator.h"

namespace dormant_tree_modeling {
namespace simulation {
namespace {

constexpr double DEG = M_PI / 180.0;

Eigen::Isometry3d laserAt(double x, double y, double z, double yaw = 0.0) {
  return geometry::laserPose(geometry::platformPose(x, y, z, yaw), geometry::StageGeometry{}, 0.0);
}

Scene groundOnly() {
  Scene s;
  s.has_ground = true;
  return s;
}

void addPost(Scene& s, double x, double y, double radius) {
  Post p;
  p.base = {x, y, 0.0};
  p.height = 3.0;
  p.radius = radius;
  s.posts.push_back(p);
}

TEST(Lms111Config, ValidatesPairingAndRanges) {
  Lms111Config c;
  EXPECT_NO_THROW(c.validate());
  EXPECT_EQ(c.beamCount(), 1080);
  c.angular_resolution_deg = 0.5;
  EXPECT_THROW(c.validate(), Error);  // 0.5 deg needs 50 Hz
  c.scan_frequency_hz = 50.0;
  EXPECT_NO_THROW(c.validate());
  EXPECT_EQ(c.beamCount(), 540);
  c.beam_samples = 3;
  EXPECT_THROW(c.validate(), Error);
}

TEST(Lms111Model, RangeNoiseAndBiasMatchTheConfiguration) {
  const Scene scene = groundOnly();
  const RayCaster caster(scene);
  Lms111Config config;
  config.beam_samples = 1;
  config.range_noise_sigma = 0.012;
  config.range_bias = 0.010;
  const Lms111Model model(caster, config);
  const double h = 1.5;
  double sum = 0.0, sum2 = 0.0;
  int n = 0;
  for (int line = 0; line < 60; ++line) {
    Rng rng = Rng::derive(42, line);
    const ScanLine scan = model.scanLine(laserAt(0, 0, h), rng);
    for (int j = 0; j < config.beamCount(); ++j) {
      const double phi = model.beamAngle(j);
      if (std::abs(phi) > 40.0 * DEG)
        continue;
      ASSERT_GT(scan.ranges[j], 0.0f) << "beam " << j;
      const double residual = scan.ranges[j] - h / std::cos(phi) - config.range_bias;
      sum += residual;
      sum2 += residual * residual;
      ++n;
    }
  }
  ASSERT_GT(n, 15000);
  const double mean = sum / n;
  const double sd = std::sqrt(sum2 / n - mean * mean);
  EXPECT_NEAR(mean, 0.0, 0.0005);        // > 3 standard errors of the mean
  EXPECT_NEAR(sd, 0.012, 0.012 * 0.05);  // > 6 standard errors of the deviation
}

TEST(Lms111Model, InvalidReturnsWhereTheDeviceReportsNone) {
  Scene scene;
  scene.has_ground = false;
  addPost(scene, 0.4, 0.0, 0.1);    // surface at 0.3 m, inside the minimum range
  addPost(scene, 0.0, 19.5, 0.5);   // surface at 19.0 m: valid
  addPost(scene, 0.0, -25.5, 0.5);  // surface at 25 m: beyond the maximum range
  const RayCaster caster(scene);
  Lms111Config config;
  config.range_noise_sigma = 0.0;
  const Lms111Model model(caster, config);
  Rng rng(1);
  auto beamAt = [&](double phi_deg) {
    return static_cast<int>(
        std::lround((phi_deg - config.start_angle_deg) / config.angular_resolution_deg));
  };
  // Looking along +x (phi 90) the near post; along +y and -y the others need yawed lasers.
  ScanLine line = model.scanLine(laserAt(0, 0, 1.0), rng);
  EXPECT_EQ(line.ranges[beamAt(90.0)], 0.0f);   // too near
  EXPECT_EQ(line.ranges[beamAt(180.0)], 0.0f);  // straight up: sky
  EXPECT_EQ(line.ranges[beamAt(0.0)], 0.0f);    // straight down: no ground in this scene
  line = model.scanLine(laserAt(0, 0, 1.0, M_PI / 2), rng);
  EXPECT_NEAR(line.ranges[beamAt(90.0)], 19.0, 0.01);
  EXPECT_EQ(line.labels[beamAt(90.0)].part, Part::POST);
  line = model.scanLine(laserAt(0, 0, 1.0, -M_PI / 2), rng);
  EXPECT_EQ(line.ranges[beamAt(90.0)], 0.0f);  // too far
}

TEST(Lms111Model, GrazingIncidenceDropsOut) {
  const Scene scene = groundOnly();
  const RayCaster caster(scene);
  Lms111Config config;
  const Lms111Model model(caster, config);
  int steep_valid = 0, steep = 0, grazing_valid = 0, grazing = 0;
  for (int line = 0; line < 20; ++line) {
    Rng rng = Rng::derive(5, line);
    const ScanLine scan = model.scanLine(laserAt(0, 0, 1.0), rng);
    for (int j = 0; j < config.beamCount(); ++j) {
      const double phi = std::abs(model.beamAngle(j)) / DEG;
      if (phi < 60.0) {
        ++steep;
        steep_valid += scan.ranges[j] > 0.0f;
      } else if (phi > 88.0 && phi < 90.0) {
        ++grazing;
        grazing_valid += scan.ranges[j] > 0.0f;
      }
    }
  }
  EXPECT_EQ(steep_valid, steep);
  EXPECT_EQ(grazing_valid, 0) << "of " << grazing;
}

TEST(Lms111Model, MixedPixelsOnlyAtDepthEdges) {
  Scene scene;
  scene.has_ground = false;
  addPost(scene, 1.5, 0.0, 0.04);  // a thin trunk at 1.5 m
  addPost(scene, 2.85, 0.0, 1.0);  // a wide surface 0.31 m behind it: echoes merge
  const RayCaster caster(scene);
  Lms111Config config;
  config.range_noise_sigma = 0.0;
  const Lms111Model model(caster, config);
  acquisition::ViewPlanConfig sweep;
  sweep.theta_min_deg = -10.0;
  sweep.theta_max_deg = 10.0;
  const auto stage = geometry::stagePose(geometry::platformPose(0, 0, 1.0, 0), {}, 0.0);
  const SimulatedView view = simulateView(model, stage, {}, sweep, 3, 0, 1);
  const auto& img = view.image;
  // Distance of each pixel's central ray: the surface a thin beam would measure.
  std::vector<double> centre(img.range.size(), -1.0);
  for (int i = 0; i < img.rows; ++i) {
    const auto laser = geometry::laserPose(stage, {}, img.theta(i));
    for (int j = 0; j < img.cols; ++j) {
      const double phi = img.phi(j);
      const Ray ray{laser.translation(),
                    laser.linear() * Eigen::Vector3d(std::sin(phi), 0, -std::cos(phi))};
      const auto hit = caster.cast(ray, 1e-4, 30.0);
      centre[static_cast<std::size_t>(i) * img.cols + j] = hit ? hit->t : -1.0;
    }
  }
  int mixed = 0;
  for (int i = 0; i < img.rows; ++i) {
    for (int j = 0; j < img.cols; ++j) {
      const std::size_t k = static_cast<std::size_t>(i) * img.cols + j;
      if (!(img.range[k] > 0.0f) || centre[k] < 0.0 || std::abs(img.range[k] - centre[k]) < 0.005)
        continue;
      ++mixed;
      // The beam is wider than the pixel spacing (LMS1xx manual 3.6.2), so an edge can mix
      // pixels as far away as the beam's radius reaches.
      const double r = centre[k];
      const double beam_radius = 0.5 * config.beam_exit_diameter + 0.5 * config.beam_divergence * r;
      const int reach_rows = static_cast<int>(std::ceil(beam_radius / (r * img.theta_step)));
      const int reach_cols = static_cast<int>(std::ceil(beam_radius / (r * img.phi_step)));
      bool edge = false;
      for (int di = -reach_rows; di <= reach_rows && !edge; ++di) {
        for (int dj = -reach_cols; dj <= reach_cols && !edge; ++dj) {
          const int row = i + di, col = j + dj;
          if (row < 0 || col < 0 || row >= img.rows || col >= img.cols)
            continue;
          const double other = centre[static_cast<std::size_t>(row) * img.cols + col];
          edge = other < 0.0 || std::abs(other - centre[k]) > 0.1;
        }
      }
      EXPECT_TRUE(edge) << "mixed pixel away from a depth edge at " << i << "," << j;
    }
  }
  EXPECT_GT(mixed, 20);  // the scene does produce mixed pixels at the trunk's silhouette
}

TEST(ViewSimulator, FullViewIsA200By1080ImageIndependentOfThreads) {
  const Scene scene = groundOnly();
  const RayCaster caster(scene);
  const Lms111Model model(caster, Lms111Config{});
  const acquisition::ViewPlanConfig sweep;
  const auto stage = geometry::stagePose(geometry::platformPose(0, -1.5, 1.5, M_PI / 2), {}, 0.0);
  const SimulatedView one = simulateView(model, stage, {}, sweep, 9, 4, 1);
  const SimulatedView two = simulateView(model, stage, {}, sweep, 9, 4, 2);
  EXPECT_EQ(one.image.rows, 200);
  EXPECT_EQ(one.image.cols, 1080);
  EXPECT_EQ(one.image.range.size(), 200u * 1080u);
  EXPECT_EQ(one.image.range, two.image.range);
  EXPECT_GT(one.image.validCount(), 1000u);
  const SimulatedView other_seed = simulateView(model, stage, {}, sweep, 10, 4, 2);
  EXPECT_NE(one.image.range, other_seed.image.range);
}

}  // namespace
}  // namespace simulation
}  // namespace dormant_tree_modeling
