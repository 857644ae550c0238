// The diameter calibration: the noise part every scanner shares, the footprint part a rig scan
// gives, the calibration file, and a tree of the rig's world measured through it.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <functional>
#include <numeric>

#include "dormant_tree_modeling/calibration/rig_calibration.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/random.h"
#include "dormant_tree_modeling/evaluation/matching.h"
#include "dormant_tree_modeling/io/point_cloud_io.h"
#include "dormant_tree_modeling/io/tree_json.h"
#include "dormant_tree_modeling/modeling/noise_bias.h"
#include "dormant_tree_modeling/modeling/sensor_calibration.h"
#include "dormant_tree_modeling/modeling/tree_modeler.h"
#include "dormant_tree_modeling/modeling/trunk_model.h"
#include "dormant_tree_modeling/registration/multi_view.h"
#include "dormant_tree_modeling/simulation/calibration_rig.h"
#include "dormant_tree_modeling/simulation/dataset.h"
#include "temp_dir.h"

namespace dormant_tree_modeling {
namespace {

using calibration::RigScan;

TEST(NoiseBias, ThickSectionsAreUnbiasedAndThinRodsWidenWithTheNoise) {
  const modeling::ModelerConfig config;
  const auto trunk = modeling::trunkNoiseBias(config);
  const auto branch = modeling::branchNoiseBias(config);
  ASSERT_TRUE(trunk.valid());
  ASSERT_TRUE(branch.valid());
  // The surface mode of a thick section under low noise is the surface.
  EXPECT_LT(std::abs(trunk.biasAt(0.05, 0.003)), 0.0005);
  // An RMS distance carries the noise: a 3 mm rod under 12 mm noise looks much wider, and more
  // so than under 3 mm.
  EXPECT_GT(branch.biasAt(0.003, 0.012), 0.003);
  EXPECT_GT(branch.biasAt(0.003, 0.012), branch.biasAt(0.003, 0.003) + 0.002);
  // Seeded: the same tables again.
  EXPECT_EQ(modeling::trunkNoiseBias(config).bias, trunk.bias);
}

/// A vertical trunk of radius r, 1 m tall, seen from 8 views all around by level beams, each
/// return displaced by Gaussian range noise sigma along its beam.
modeling::Points noisyTrunk(double r, double sigma, std::uint64_t seed) {
  Rng rng(seed);
  modeling::Points pts;
  for (int v = 0; v < 8; ++v) {
    const double az = 2.0 * M_PI * v / 8;
    const Eigen::Vector3d b(std::cos(az), std::sin(az), 0.0);
    const Eigen::Vector3d across(-b.y(), b.x(), 0.0);
    for (int k = 0; k < 3000; ++k) {
      const double u = rng.uniform(-r, r);
      pts.push_back(u * across - std::sqrt(r * r - u * u) * b + sigma * rng.normal() * b +
                    Eigen::Vector3d(0.0, 0.0, rng.uniform(0.0, 1.0)));
    }
  }
  return pts;
}

TEST(NoiseBias, TheTablesReadTheNoiseAsFiveCentimetreSlicesDoOnAnyTrunk) {
  const modeling::ModelerConfig config;
  const double sigma = 0.012;
  std::vector<modeling::TrunkModel> trunks;
  for (const double r : {0.022, 0.05}) {
    const auto pts = noisyTrunk(r, sigma, 17);
    std::vector<int> region(pts.size());
    std::iota(region.begin(), region.end(), 0);
    trunks.push_back(modeling::modelTrunk(pts, region, {{0, 0, 0}, {0, 0, 1}}, r, config));
  }
  const auto& thin = trunks[0];
  const auto& thick = trunks[1];
  // The estimator keeps residuals within half a slice's radius: a trunk of 22 mm reads the same
  // noise a third below one of 50 mm (7.0 against 10.5 mm) ...
  EXPECT_LT(thin.noise_sigma, 0.75 * thick.noise_sigma);
  // ... and the tables read both much as 5 cm slices do (9.9 and 10.7 mm).
  const double raw_gap = thick.noise_sigma - thin.noise_sigma;
  EXPECT_LT(std::abs(thick.table_sigma - thin.table_sigma), 0.3 * raw_gap);
  EXPECT_NEAR(thin.table_sigma, thick.table_sigma, 0.1 * thick.table_sigma);
  EXPECT_NEAR(thick.table_sigma, thick.noise_sigma, 0.05 * thick.noise_sigma);
  // Read on 5 cm slices, or on none, it stays as it is.
  EXPECT_NEAR(modeling::standardNoiseReading(config, 0.008, {0.05}), 0.008, 1e-12);
  EXPECT_EQ(modeling::standardNoiseReading(config, 0.008, {}), 0.008);
}

TEST(NoiseBias, TheFootprintIsAddedWithItsNoiseHeldToItsRows) {
  modeling::RadiusCalibration noise_part;
  noise_part.radii = {0.01, 0.02};
  noise_part.noise = {0.002, 0.004, 0.020};
  noise_part.bias = {0.001, 0.0, 0.002, 0.001, 0.006, 0.004};
  modeling::RadiusCalibration footprint;
  footprint.radii = {0.01, 0.02};
  footprint.noise = {0.003, 0.005};
  footprint.bias = {0.004, 0.002, 0.006, 0.004};
  const auto sum = modeling::addFootprint(noise_part, footprint);
  ASSERT_EQ(sum.bias.size(), 6u);
  EXPECT_NEAR(sum.bias[0], 0.001 + 0.004, 1e-12);  // below the footprint's rows: its lowest
  EXPECT_NEAR(sum.bias[3], 0.001 + 0.003, 1e-12);  // 4 mm: halfway between its rows
  EXPECT_NEAR(sum.bias[4], 0.006 + 0.006, 1e-12);  // 20 mm: its highest row, not extrapolated
  EXPECT_EQ(modeling::addFootprint(noise_part, {}).bias, noise_part.bias);
}

TEST(SensorCalibrationFile, RoundTripsAndNamesWhatIsWrong) {
  test::TempDir dir;
  modeling::SensorCalibration c;
  c.name = "unit 1234";
  c.sources = {"rig.pcd"};
  c.trunk_footprint.radii = {0.01, 0.05};
  c.trunk_footprint.noise = {0.006};
  c.trunk_footprint.bias = {0.003, 0.001};
  c.branch_footprint = c.trunk_footprint;
  c.coverage = {0.01, 0.05, 0.003, 0.02, 0.006, 0.006};
  c.silhouette = {true, 0.0015, 0.0085, 1.2, 3.4, 0.5, 0.4};
  c.noise_readings = {{{0.02, 0.05}, {0.007, 0.006}}};
  const std::string path =
      dir.write("cal.yaml", modeling::sensorCalibrationToYaml(c, "made by a test"));
  const auto back = modeling::loadSensorCalibration(path);
  EXPECT_EQ(back.name, c.name);
  EXPECT_EQ(back.sources, c.sources);
  EXPECT_EQ(back.trunk_footprint.bias, c.trunk_footprint.bias);
  EXPECT_DOUBLE_EQ(back.coverage.branch_radius_max_m, 0.02);
  EXPECT_EQ(back.hash.size(), 16u);
  EXPECT_TRUE(back.silhouette.measured);
  EXPECT_DOUBLE_EQ(back.silhouette.growth_per_m, 0.0085);
  ASSERT_EQ(back.noise_readings.size(), 1u);
  EXPECT_EQ(back.noise_readings[0].radii_m, c.noise_readings[0].radii_m);
  EXPECT_EQ(back.noise_readings[0].noise_m, c.noise_readings[0].noise_m);
  registration::RegistrationConfig reg;
  EXPECT_TRUE(registration::applySensorCalibration(back, reg));
  EXPECT_DOUBLE_EQ(reg.axes.silhouette_growth_m, 0.5 * 0.0015);
  EXPECT_DOUBLE_EQ(reg.axes.silhouette_diameter_gain, 0.4);
  // Axis samples stay within the silhouettes of the rods the calibration covers (up to 0.02 m
  // radius), 15 % wider.
  const double slack = 1.0 + modeling::COVERAGE_RADIUS_SLACK;
  EXPECT_DOUBLE_EQ(reg.axes.max_width_m, slack * (2 * 0.4 * 0.02 + 0.0015));
  EXPECT_DOUBLE_EQ(reg.axes.max_width_per_m, slack * 0.0085);
  modeling::SensorCalibration without = back;
  without.silhouette = {};
  registration::RegistrationConfig ideal;
  EXPECT_FALSE(registration::applySensorCalibration(without, ideal));
  EXPECT_DOUBLE_EQ(ideal.axes.silhouette_growth_per_m, 0.0);
  EXPECT_DOUBLE_EQ(ideal.axes.max_width_m, 0.0);
  auto code = [&](const std::string& text) {
    try {
      modeling::loadSensorCalibration(dir.write("bad.yaml", text));
    } catch (const Error& e) {
      return e.code();
    }
    return ErrorCode::IO_FAILURE;  // not thrown: fails the comparisons below
  };
  const std::string good = modeling::sensorCalibrationToYaml(c, "");
  auto replaced = [&](const std::string& from, const std::string& to) {
    std::string t = good;
    t.replace(t.find(from), from.size(), to);
    return t;
  };
  EXPECT_EQ(code("tree_modeler:\n  psi_t: 60\n"), ErrorCode::PARSE_ERROR);
  EXPECT_EQ(code(replaced("radii_m: [0.01, 0.05]", "radii_m: [0.05, 0.01]")),
            ErrorCode::INVALID_ARGUMENT);
  EXPECT_EQ(code(replaced("bias_m: [0.003", "bias_m: [0.3")), ErrorCode::INVALID_ARGUMENT);
  EXPECT_EQ(code(replaced("covers:", "coverage:")), ErrorCode::PARSE_ERROR);
  EXPECT_EQ(code(replaced("noise_m: [0.006]", "noise_m: six")), ErrorCode::PARSE_ERROR);
  EXPECT_EQ(code(replaced("noise_m: [0.007, 0.006]", "noise_m: [0.007]")),
            ErrorCode::INVALID_ARGUMENT);
  EXPECT_EQ(code(replaced("noise_m: [0.007, 0.006]", "noise_m: [0.007, 0]")),
            ErrorCode::INVALID_ARGUMENT);
  EXPECT_EQ(code(replaced("- radii_m: [0.02", "- radius_m: [0.02")), ErrorCode::PARSE_ERROR);
  // Files from before the readings were recorded load; the modeler says they are old.
  const std::string no_readings = replaced(
      "  noise_readings:\n    - radii_m: [0.02, 0.05]\n      noise_m: "
      "[0.007, 0.006]\n",
      "");
  EXPECT_TRUE(
      modeling::loadSensorCalibration(dir.write("older.yaml", no_readings)).noise_readings.empty());
  // A gain this low would multiply the width's noise tenfold into the radius.
  EXPECT_EQ(code(replaced("diameter_gain: [0.4]", "diameter_gain: [0.1]")),
            ErrorCode::INVALID_ARGUMENT);
  // Files from before the gain was measured: the footprint only adds a margin.
  EXPECT_DOUBLE_EQ(modeling::loadSensorCalibration(
                       dir.write("old.yaml", replaced("\n    diameter_gain: [0.4]", "")))
                       .silhouette.diameter_gain,
                   1.0);
  EXPECT_THROW(modeling::loadSensorCalibration(dir.file("missing.yaml")), Error);
  // Another file, another hash.
  EXPECT_NE(
      modeling::loadSensorCalibration(dir.write("other.yaml", replaced("unit 1234", "unit 99")))
          .hash,
      back.hash);
}

TEST(SensorCalibrationFile, AWrittenFileLoadsBackAsTheSameNumbers) {
  test::TempDir dir;
  // Values as a measurement leaves them, not short decimals.
  const double k = 4.0 / 3.0;
  modeling::SensorCalibration c;
  c.name = "measured";
  c.trunk_footprint.radii = {0.008, 0.0125 + 1e-7 * k, 0.05};
  c.trunk_footprint.noise = {0.0086925, 0.0121 * k};
  c.trunk_footprint.bias = {0.0052013 * k, 0.0047, -0.00084 * k, 0.0061, 0.005 * k, 1e-9 * k};
  c.branch_footprint.radii = {0.002, 0.0065 * k};
  c.branch_footprint.noise = {0.0086925};
  c.branch_footprint.bias = {0.008140901744318, 0.0061747499 * k};
  c.coverage = {0.008, 0.1 * k, 0.002, 0.02 * k, 0.0086925, 0.0121 * k};
  c.silhouette = {true, 0.0239 * k, 0.0083 * k, 1.21 * k, 3.45, 0.7 * k, 0.4 * k};
  c.noise_readings = {{{0.0125, 0.05 * k}, {0.00828 * k, 0.00869}}};
  const auto back = modeling::loadSensorCalibration(
      dir.write("cal.yaml", modeling::sensorCalibrationToYaml(c, "")));
  const auto same = [](const modeling::RadiusCalibration& a, const modeling::RadiusCalibration& b) {
    EXPECT_EQ(a.radii, b.radii);
    EXPECT_EQ(a.noise, b.noise);
    EXPECT_EQ(a.bias, b.bias);
  };
  same(back.trunk_footprint, c.trunk_footprint);
  same(back.branch_footprint, c.branch_footprint);
  EXPECT_EQ(back.coverage.trunk_radius_max_m, c.coverage.trunk_radius_max_m);
  EXPECT_EQ(back.coverage.branch_radius_max_m, c.coverage.branch_radius_max_m);
  EXPECT_EQ(back.coverage.noise_max_m, c.coverage.noise_max_m);
  ASSERT_EQ(back.noise_readings.size(), 1u);
  EXPECT_EQ(back.noise_readings[0].radii_m, c.noise_readings[0].radii_m);
  EXPECT_EQ(back.noise_readings[0].noise_m, c.noise_readings[0].noise_m);
  EXPECT_EQ(back.silhouette.growth_m, c.silhouette.growth_m);
  EXPECT_EQ(back.silhouette.growth_per_m, c.silhouette.growth_per_m);
  EXPECT_EQ(back.silhouette.range_min_m, c.silhouette.range_min_m);
  EXPECT_EQ(back.silhouette.depth_share, c.silhouette.depth_share);
  EXPECT_EQ(back.silhouette.diameter_gain, c.silhouette.diameter_gain);
}

// Samples on rods of 4-40 mm seen at 1.2-3.0 m whose widths follow width(diameter, range).
std::vector<calibration::SilhouetteSample> silhouettes(
    const std::function<double(double, double)>& width) {
  std::vector<calibration::SilhouetteSample> out;
  for (const double d : {0.004, 0.006, 0.01, 0.016, 0.025, 0.04}) {
    for (const double range : {1.2, 1.8, 2.4, 3.0})
      out.push_back({range, width(d, range), d, 0.0});
  }
  return out;
}

TEST(SilhouetteModel, GainMarginAndSlopeComeBackFromTheRods) {
  auto wide = [](double d, double range) { return 0.4 * d + 0.024 + 0.008 * range; };
  std::vector<std::string> warnings;
  auto s = calibration::fitSilhouette(silhouettes(wide), &warnings);
  EXPECT_TRUE(s.measured);
  EXPECT_NEAR(s.diameter_gain, 0.4, 1e-9);
  EXPECT_NEAR(s.growth_m, 0.024, 1e-9);
  EXPECT_NEAR(s.growth_per_m, 0.008, 1e-9);
  EXPECT_DOUBLE_EQ(s.range_min_m, 1.2);
  EXPECT_DOUBLE_EQ(s.range_max_m, 3.0);
  EXPECT_TRUE(warnings.empty());
  // A sample across two rods reads 5 cm wide: the refit leaves it out.
  auto crossed = silhouettes(wide);
  for (std::size_t i = 0; i < crossed.size(); i += 10)
    crossed[i].width += 0.05;
  s = calibration::fitSilhouette(crossed, &warnings);
  EXPECT_NEAR(s.diameter_gain, 0.4, 1e-9);
  EXPECT_NEAR(s.growth_m, 0.024, 1e-9);
  // Rods of one diameter cannot show the gain: 1, the width less the diameter is the margin.
  auto one_diameter = silhouettes(wide);
  for (auto& g : one_diameter) {
    g.diameter = 0.01;
    g.width = wide(0.01, g.range);
  }
  s = calibration::fitSilhouette(one_diameter, &warnings);
  EXPECT_DOUBLE_EQ(s.diameter_gain, 1.0);
  EXPECT_NEAR(s.growth_m, 0.004 + 0.024 - 0.01, 1e-9);
  EXPECT_NEAR(s.growth_per_m, 0.008, 1e-9);
  // Seen at one range: no slope, the margin at that range.
  auto one_range = silhouettes(wide);
  for (auto& g : one_range) {
    g.range = 2.0;
    g.width = wide(g.diameter, 2.0);
  }
  s = calibration::fitSilhouette(one_range, &warnings);
  EXPECT_DOUBLE_EQ(s.growth_per_m, 0.0);
  EXPECT_NEAR(s.growth_m, 0.024 + 0.016, 1e-9);
  EXPECT_NEAR(s.diameter_gain, 0.4, 1e-9);
  EXPECT_TRUE(warnings.empty());
  EXPECT_THROW(calibration::fitSilhouette({}, &warnings), Error);
}

TEST(SilhouetteModel, AGainTooLowToReadIsHeldAtTheBoundAndSaid) {
  // Widths that hardly follow the diameter: a radius read from them would be noise.
  const auto samples =
      silhouettes([](double d, double range) { return 0.1 * d + 0.03 + 0.004 * range; });
  std::vector<std::string> warnings;
  const auto s = calibration::fitSilhouette(samples, &warnings);
  EXPECT_DOUBLE_EQ(s.diameter_gain, modeling::MIN_DIAMETER_GAIN);
  ASSERT_EQ(warnings.size(), 1u);
  EXPECT_NE(warnings[0].find("0.10 of the rods' diameter"), std::string::npos) << warnings[0];
  // The margin is refitted for the held gain: the rods' mean width stays where it was.
  double measured = 0, modelled = 0;
  for (const auto& g : samples) {
    measured += g.width;
    modelled += s.diameter_gain * g.diameter + s.growth_m + s.growth_per_m * g.range;
  }
  EXPECT_NEAR(modelled, measured, 1e-9);
}

TEST(SensorCalibrationFile, OldTablesInTheModelerParametersAreRefusedWithTheWayOut) {
  test::TempDir dir;
  for (const char* key : {"beam_exit", "beam_divergence", "silhouette_fraction"}) {
    try {
      registration::loadRegistrationConfig(dir.write("reg.yaml", std::string(key) + ": 0.3\n"));
      FAIL() << key << " accepted";
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::PARSE_ERROR);
      EXPECT_NE(std::string(e.what()).find("calibrate_diameters"), std::string::npos);
    }
  }
  try {
    modeling::loadModelerConfig(dir.write("old.yaml", "trunk_calibration_radii: [0.01]\n"));
    FAIL() << "accepted";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::PARSE_ERROR);
    EXPECT_NE(std::string(e.what()).find("calibrate_diameters"), std::string::npos);
  }
}

TEST(SensorCalibrationFile, TheShippedSensorModelCalibrationLoads) {
  const auto c = modeling::loadSensorCalibration(std::string(DTM_TEST_DATA_DIR) +
                                                 "/../../config/calibration/lms111_model.yaml");
  EXPECT_EQ(c.name, "lms111_model");
  EXPECT_EQ(c.trunk_footprint.noise.size(), 3u);
  EXPECT_LE(c.coverage.branch_radius_min_m, 0.003);
}

TEST(SensorCalibrationFile, MapsATreesNoiseReadingToTheRigsFiveCentimetreSection) {
  modeling::SensorCalibration c;
  c.name = "two scans";
  // Two rig scans: the thin sections read more than the 5 cm one (a footprint), at two noises.
  c.noise_readings = {{{0.02, 0.05, 0.10}, {0.008, 0.006, 0.004}},
                      {{0.02, 0.05, 0.10}, {0.012, 0.010, 0.008}}};
  EXPECT_DOUBLE_EQ(c.noise_readings[0].at(0.035), 0.007);
  EXPECT_DOUBLE_EQ(c.noise_readings[0].at(0.01), 0.008);  // held beyond the sections
  EXPECT_DOUBLE_EQ(c.noise_readings[1].at(0.2), 0.008);
  // A tree read on 2 cm slices: the scans read 8 and 12 mm there, 6 and 10 mm on 5 cm.
  EXPECT_NEAR(c.standardReading(0.008, {0.02}), 0.006, 1e-12);
  EXPECT_NEAR(c.standardReading(0.010, {0.02, 0.02}), 0.008, 1e-12);
  EXPECT_NEAR(c.standardReading(0.016, {0.02}), 0.016 * 0.010 / 0.012, 1e-12);
  EXPECT_NEAR(c.standardReading(0.004, {0.02}), 0.004 * 0.006 / 0.008, 1e-12);
  // Slices of 2 and 10 cm: the scans read their mean, 6 and 10 mm, as on 5 cm.
  EXPECT_NEAR(c.standardReading(0.009, {0.02, 0.10}), 0.009, 1e-12);
  // Nothing to map with: the estimate as read.
  EXPECT_DOUBLE_EQ(c.standardReading(0.009, {}), 0.009);
  EXPECT_DOUBLE_EQ(modeling::SensorCalibration{}.standardReading(0.009, {0.02}), 0.009);
}

/// The simulated rig scanned with the whole plan at 6 mm noise, once for the suite.
class RigCalibration : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    dir_ = new test::TempDir;
    simulation::DatasetConfig o;
    o.orchard.preset = simulation::CALIBRATION_RIG_PRESET;
    o.sensor.range_noise_sigma = 0.006;
    simulation::writeDataset(o, dir_->file("rig"));
    scan_ = new RigScan;
    scan_->name = "rig";
    scan_->rig = io::readTruthFile(dir_->file("rig/truth.json"));
    scan_->points = io::readPointsInFileFrame(dir_->file("rig/target.pcd"));
  }
  static void TearDownTestSuite() {
    delete scan_;
    delete dir_;
  }
  static test::TempDir* dir_;
  static RigScan* scan_;
};
test::TempDir* RigCalibration::dir_ = nullptr;
RigScan* RigCalibration::scan_ = nullptr;

TEST_F(RigCalibration, EveryPartIsFoundAndTheFootprintShrinksWithTheRadius) {
  const auto result = calibration::calibrateFromRig({*scan_}, modeling::ModelerConfig{}, "sim");
  ASSERT_EQ(result.warnings.size(), 1u);  // a cloud: no silhouette
  EXPECT_NE(result.warnings[0].find("given as a cloud"), std::string::npos);
  int sections = 0, rods = 0;
  for (const auto& s : result.samples)
    (s.trunk ? sections : rods)++;
  EXPECT_EQ(sections, 7);
  EXPECT_EQ(rods, 20);
  const auto& c = result.calibration;
  ASSERT_TRUE(c.trunk_footprint.valid());
  ASSERT_TRUE(c.branch_footprint.valid());
  // Our sensor model's beam widens thin objects by millimetres, thick ones hardly.
  const auto& t = c.branch_footprint.bias;
  EXPECT_GT(t.front(), 0.002);
  EXPECT_LT(t.front(), 0.010);
  for (std::size_t i = 1; i < t.size(); ++i)
    EXPECT_LE(t[i], t[i - 1]);
  EXPECT_LT(std::abs(c.trunk_footprint.bias.back()), 0.001);
  EXPECT_NEAR(c.coverage.branch_radius_min_m, 0.002, 1e-9);
  EXPECT_NEAR(c.coverage.trunk_radius_max_m, 0.1, 1e-9);
  // The noise read section by section; the rows are keyed on the 5 cm section's reading.
  ASSERT_EQ(c.noise_readings.size(), 1u);
  const auto& reading = c.noise_readings[0];
  EXPECT_GE(reading.radii_m.size(), 4u);
  EXPECT_NEAR(reading.radii_m.back(), 0.1, 1e-9);
  const double standard = reading.at(modeling::STANDARD_READING_RADIUS_M);
  EXPECT_GT(standard, 0.004);
  EXPECT_LT(standard, 0.009);
  EXPECT_DOUBLE_EQ(c.coverage.noise_min_m, standard);
  EXPECT_EQ(c.trunk_footprint.noise, std::vector<double>{standard});
  // Our beam widens the thinnest rods more than it widens thicker ones by their extra radius:
  // the tables cannot tell branches a little thicker than the floor from it.
  ASSERT_EQ(result.branch_floor_reach.size(), 1u);
  EXPECT_DOUBLE_EQ(result.branch_floor_reach[0].noise_m, standard);
  EXPECT_GT(result.branch_floor_reach[0].radius_m, 0.0025);
  EXPECT_LT(result.branch_floor_reach[0].radius_m, c.coverage.branch_radius_max_m);
}

TEST_F(RigCalibration, TheRigsViewsGiveTheSilhouetteGrowthOfTheBeam) {
  const RigScan views = calibration::readRigViews(dir_->file("rig"), scan_->rig);
  EXPECT_EQ(views.views.size(), 40u);
  const auto r = calibration::calibrateFromRig({views}, modeling::ModelerConfig{}, "sim");
  const auto& s = r.calibration.silhouette;
  ASSERT_TRUE(s.measured);
  // Our sensor model's beam: 8 mm + 15 mrad, 38 mm across at 2 m; a beam a few tenths on a rod
  // still returns with the rod's range, so at 2 m a 10 mm rod's silhouette grows by about half
  // of that.
  const double at_2m = s.growth_m + 2.0 * s.growth_per_m - (1.0 - s.diameter_gain) * 0.01;
  EXPECT_GT(at_2m, 0.010);
  EXPECT_LT(at_2m, 0.030);
  EXPECT_GT(s.growth_per_m, 0.0);
  // A beam that wide also lets a thin rod catch more of it than a thick one gains: the width
  // follows the diameter only in part.
  EXPECT_GT(s.diameter_gain, 0.5);
  EXPECT_LT(s.diameter_gain, 0.95);
  std::printf("[ INFO ] width %.2f x diameter + %.2f mm + %.2f mm/m, share %.2f\n", s.diameter_gain,
              1000 * s.growth_m, 1000 * s.growth_per_m, s.depth_share);
  EXPECT_LT(s.range_min_m, 1.6);
  // The wings carry the near surface's range: the axes' depth wants part of the growth only.
  EXPECT_GT(s.depth_share, 0.3);
  EXPECT_LT(s.depth_share, 0.9);
  // The same rig as a cloud cannot tell the sides apart: said, and nothing measured.
  const auto cloud = calibration::calibrateFromRig({*scan_}, modeling::ModelerConfig{}, "sim");
  EXPECT_FALSE(cloud.calibration.silhouette.measured);
  ASSERT_EQ(cloud.warnings.size(), 1u);
  EXPECT_NE(cloud.warnings[0].find("not calibrated"), std::string::npos);
}

TEST_F(RigCalibration, SurveyCoordinatesGiveTheSameCalibration) {
  RigScan far = *scan_;
  const Eigen::Vector3d offset(612345.0, 4423456.0, 210.0);
  for (auto& p : far.points)
    p += offset;
  for (auto* line : {&far.rig.trunk}) {
    for (auto& p : line->points)
      p += offset;
  }
  for (auto& b : far.rig.primary_branches) {
    for (auto& p : b.points)
      p += offset;
  }
  const auto a = calibration::calibrateFromRig({*scan_}, modeling::ModelerConfig{}, "a");
  const auto b = calibration::calibrateFromRig({far}, modeling::ModelerConfig{}, "b");
  ASSERT_EQ(a.calibration.branch_footprint.bias.size(), b.calibration.branch_footprint.bias.size());
  for (std::size_t i = 0; i < a.calibration.branch_footprint.bias.size(); ++i)
    EXPECT_NEAR(a.calibration.branch_footprint.bias[i], b.calibration.branch_footprint.bias[i],
                2e-4);
}

TEST_F(RigCalibration, BadRigFilesAndScansGiveErrorsOrWarningsNeverASilentTable) {
  const modeling::ModelerConfig config;
  // An empty scan.
  RigScan empty = *scan_;
  empty.points.clear();
  EXPECT_THROW(calibration::calibrateFromRig({empty}, config, "x"), Error);
  // Rods that are not in the scan: the rig file's rods 1.5 m beside the pipe.
  RigScan turned = *scan_;
  for (auto& b : turned.rig.primary_branches) {
    for (auto& p : b.points)
      p.x() += 1.5;
  }
  try {
    calibration::calibrateFromRig({turned}, config, "x");
    FAIL() << "a table from rods that are not there";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::NO_TRUNK);
    EXPECT_NE(std::string(e.what()).find("no rod"), std::string::npos) << e.what();
  }
  // One rod's axis 20 cm off: named, the rest measured.
  RigScan off = *scan_;
  for (auto& p : off.rig.primary_branches[4].points)
    p.x() += 0.2;
  const auto r = calibration::calibrateFromRig({off}, config, "x");
  ASSERT_EQ(r.warnings.size(), 2u);  // and the cloud's silhouette
  EXPECT_NE(r.warnings[0].find("rod 4 "), std::string::npos) << r.warnings[0];
  // A pipe of one diameter: said, and the table is constant over radius.
  RigScan one = *scan_;
  one.rig.trunk.points = {one.rig.trunk.points[6], one.rig.trunk.points[7]};
  one.rig.trunk.diameters = {0.06, 0.06};
  const auto single = calibration::calibrateFromRig({one}, config, "x");
  bool said = false;
  for (const auto& w : single.warnings)
    said = said || w.find("one diameter") != std::string::npos;
  EXPECT_TRUE(said);
  EXPECT_EQ(single.calibration.trunk_footprint.radii.size(), 1u);
  // No pipe section long enough, or no rods: not a rig.
  RigScan bare = *scan_;
  bare.rig.primary_branches.clear();
  EXPECT_THROW(calibration::calibrateFromRig({bare}, config, "x"), Error);
}

TEST_F(RigCalibration, ATreeOfTheSameWorldMeasuresWithinBoundsAndSaysWhichCalibration) {
  auto result = calibration::calibrateFromRig({*scan_}, modeling::ModelerConfig{}, "sim");
  result.calibration.hash = "0123456789abcdef";
  simulation::DatasetConfig o;
  o.seed = 41;  // not a bench tree
  o.sensor.range_noise_sigma = 0.006;
  o.write_views = false;
  simulation::writeDataset(o, dir_->file("tree"));
  const auto cloud = io::readPointsInFileFrame(dir_->file("tree/target.pcd"));
  const auto truth = io::readTruthFile(dir_->file("tree/truth.json"));
  modeling::ModelerConfig config;
  config.calibration = result.calibration;
  const auto model = modeling::TreeModeler(config).model(cloud).model;
  const auto score = evaluation::evaluate(model, truth);
  EXPECT_GE(score.f1, 0.9);
  EXPECT_LT(score.branch_mae, 0.006);
  EXPECT_LT(std::abs(score.branch_bias), 0.003);
  EXPECT_LT(score.trunk_mae, 0.004);
  EXPECT_EQ(model.correction.calibration, "sim");
  EXPECT_EQ(model.correction.calibration_hash, "0123456789abcdef");
  EXPECT_GT(model.correction.noise_sigma, 0.004);
  // The model file carries it.
  const auto back = io::modelFromJson(io::modelToJson(model));
  EXPECT_EQ(back.correction.calibration, "sim");
  EXPECT_EQ(back.correction.warnings, model.correction.warnings);
  EXPECT_DOUBLE_EQ(back.correction.table_noise_sigma, model.correction.table_noise_sigma);
  // Without a calibration the model says it corrected the noise alone.
  const auto plain = modeling::TreeModeler(modeling::ModelerConfig{}).model(cloud).model;
  ASSERT_FALSE(plain.correction.warnings.empty());
  EXPECT_NE(plain.correction.warnings[0].find("no sensor calibration"), std::string::npos);
  EXPECT_TRUE(plain.correction.calibration.empty());
  // The rig's rows are keyed on its 5 cm section's reading, and a calibrated tree's estimate
  // is mapped to it through the rig's readings: the same scanner at the same noise lands
  // near the rig's row. The noise part alone reads it as 5 cm slices would through the
  // estimator's model (this tree's trunk is thinner: more).
  const double row = result.calibration.coverage.noise_min_m;
  EXPECT_NEAR(model.correction.table_noise_sigma, row, 0.15 * row);
  EXPECT_NE(model.correction.table_noise_sigma, model.correction.noise_sigma);
  EXPECT_GT(plain.correction.table_noise_sigma, plain.correction.noise_sigma);
  // The search's scatter reads every slice, the range noise those on the track.
  EXPECT_GE(model.correction.search_noise_sigma, model.correction.noise_sigma);
  EXPECT_DOUBLE_EQ(back.correction.search_noise_sigma, model.correction.search_noise_sigma);
  // A file made before the readings were recorded: the model says so.
  config.calibration.noise_readings.clear();
  const auto older = modeling::TreeModeler(config).model(cloud).model;
  const auto& said = older.correction.warnings;
  EXPECT_TRUE(std::any_of(said.begin(), said.end(), [](const std::string& w) {
    return w.find("no noise readings per pipe section") != std::string::npos;
  }));
}

}  // namespace
}  // namespace dormant_tree_modeling
