#include <gtest/gtest.h>

#include <cmath>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/random.h"
#include "dormant_tree_modeling/modeling/geometry_fit.h"
#include "dormant_tree_modeling/modeling/modeler_config.h"
#include "dormant_tree_modeling/modeling/radius_calibration.h"

namespace dormant_tree_modeling {
namespace modeling {
namespace {

RadiusCalibration table() {
  RadiusCalibration c;
  c.radii = {0.01, 0.03};
  c.noise = {0.002, 0.006};
  c.bias = {0.004, 0.002,   // noise 2 mm
            0.008, 0.004};  // noise 6 mm
  return c;
}

TEST(RadiusCalibration, BilinearInsideHeldOutsideAndExtrapolatedAboveTheNoise) {
  const RadiusCalibration c = table();
  ASSERT_TRUE(c.valid());
  EXPECT_NEAR(c.biasAt(0.01, 0.002), 0.004, 1e-12);
  EXPECT_NEAR(c.biasAt(0.02, 0.002), 0.003, 1e-12);
  EXPECT_NEAR(c.biasAt(0.02, 0.004), 0.0045, 1e-12);  // mean of 3 and 6 mm
  EXPECT_NEAR(c.biasAt(0.005, 0.001), 0.004, 1e-12);  // below both axes: the corner
  // Above the noisiest row the last two rows' line continues, for at most one row spacing:
  // 8 mm is half a spacing past 6 mm, and 0.5 m is capped at 10 mm.
  EXPECT_NEAR(c.biasAt(0.01, 0.008), 0.010, 1e-12);
  EXPECT_NEAR(c.biasAt(0.5, 0.008), 0.005, 1e-12);  // radius held at 30 mm
  EXPECT_NEAR(c.biasAt(0.5, 0.5), 0.006, 1e-12);
  EXPECT_NEAR(c.biasAt(0.01, 0.5), 0.012, 1e-12);
}

TEST(RadiusCalibration, CorrectInvertsTheTable) {
  const RadiusCalibration c = table();
  for (const double r : {0.01, 0.015, 0.02, 0.03, 0.05}) {
    for (const double s : {0.002, 0.004, 0.006}) {
      const double apparent = r + c.biasAt(r, s);
      EXPECT_NEAR(c.correct(apparent, s, 0.001), r, 1e-9) << r << " " << s;
    }
  }
  EXPECT_DOUBLE_EQ(c.correct(0.002, 0.002, 0.003), 0.003);                  // floor
  EXPECT_DOUBLE_EQ(RadiusCalibration{}.correct(0.02, 0.004, 0.001), 0.02);  // empty: identity
}

TEST(RadiusCalibration, AReadingThatThinnerRadiiGiveTooIsNoMeasurement) {
  // A wide beam's table: the widening falls faster than the radius grows from 4 to 6 mm, so
  // 2, 4, 6 and 12 mm read 12, 13, 12 and 14 mm, and 12.5 mm fits 3, 5 and 7.5 mm alike;
  // only radii past 9 mm read wider than 13 mm.
  RadiusCalibration c;
  c.radii = {0.002, 0.004, 0.006, 0.012};
  c.noise = {0.005};
  c.bias = {0.010, 0.009, 0.006, 0.002};
  const auto floor = c.floorAmbiguity(0.002, 0.005);
  EXPECT_NEAR(floor.radius, 0.009, 1e-12);
  EXPECT_NEAR(floor.apparent, 0.013, 1e-12);
  // A reading no wider than the floor's is the floor; one that thinner radii read too is one
  // of its radii, and not resolved; past the ambiguity the one radius, resolved.
  EXPECT_DOUBLE_EQ(c.correct(0.0119, 0.005, 0.002), 0.002);
  EXPECT_FALSE(c.resolves(0.002, 0.005, 0.002));
  for (const double apparent : {0.0125, 0.013}) {
    const double r = c.correct(apparent, 0.005, 0.002);
    EXPECT_NEAR(r + c.biasAt(r, 0.005), apparent, 1e-9);
    EXPECT_FALSE(c.resolves(r, 0.005, 0.002)) << apparent;
  }
  EXPECT_NEAR(c.correct(0.0135, 0.005, 0.002), 0.0105, 1e-9);
  EXPECT_TRUE(c.resolves(0.0105, 0.005, 0.002));
  // Past the table the widening is held: a table ending low is ambiguous beyond its end.
  c.bias.back() = -0.0005;  // 12 mm reads 11.5 mm, 13.5 mm reads 13 mm
  EXPECT_NEAR(c.floorAmbiguity(0.002, 0.005).radius, 0.0135, 1e-12);
  // Where the apparent radius grows everywhere the floor is ambiguous with itself alone.
  const auto plain = table().floorAmbiguity(0.002, 0.004);
  EXPECT_DOUBLE_EQ(plain.radius, 0.002);
  EXPECT_TRUE(table().resolves(0.0021, 0.004, 0.002));
  EXPECT_NEAR(plain.apparent, 0.002 + table().biasAt(0.002, 0.004), 1e-12);
  EXPECT_DOUBLE_EQ(RadiusCalibration{}.floorAmbiguity(0.002, 0.004).radius, 0.002);
}

TEST(RadiusCalibration, ConfigRejectsInconsistentTables) {
  ModelerConfig config;
  config.trunk_calibration = table();
  EXPECT_NO_THROW(config.validate());
  config.trunk_calibration.bias.pop_back();
  EXPECT_THROW(config.validate(), Error);
  config.trunk_calibration = table();
  config.trunk_calibration.radii = {0.03, 0.01};
  EXPECT_THROW(config.validate(), Error);
  config.trunk_calibration = table();
  config.trunk_calibration.bias[0] = 0.2;
  EXPECT_THROW(config.validate(), Error);
  config.trunk_calibration = {};
  EXPECT_NO_THROW(config.validate());                       // no table: no correction
  EXPECT_FALSE(ModelerConfig{}.trunk_calibration.valid());  // TreeModeler fills it
}

TEST(SurfaceCircle, IgnoresABranchBaseThatPullsLeastSquaresOutwards) {
  // A trunk section of radius 30 mm seen all round with 3 mm noise, and a branch base: a
  // blob of points from the surface 30 to 80 mm outwards on one side.
  Rng rng(7);
  Points2 pts;
  for (int i = 0; i < 600; ++i) {
    const double a = rng.uniform(0.0, 2.0 * M_PI), r = 0.03 + rng.normal(0.0, 0.003);
    pts.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  for (int i = 0; i < 400; ++i) {
    const double a = rng.uniform(-0.3, 0.3), r = rng.uniform(0.03, 0.08);
    pts.emplace_back(r * std::cos(a), r * std::sin(a));
  }
  const auto ls = fitCircle(pts);
  ASSERT_TRUE(ls);
  EXPECT_GT(ls->radius, 0.034);  // the plain fit is pulled out
  CircleRansacConfig o;
  o.threshold = 0.0075;
  o.min_radius = 0.01;
  o.max_radius = 0.08;
  const auto start = ransacCircle(pts, o);
  ASSERT_TRUE(start);
  const auto s = surfaceCircle(pts, *start, 0.003, 0.01, 0.08);
  ASSERT_TRUE(s);
  EXPECT_NEAR(s->radius, 0.03, 0.0015);
  EXPECT_LT(s->center.norm(), 0.0015);
  EXPECT_FALSE(surfaceCircle({{0, 0}, {1, 0}}, *ls, 0.003, 0.01, 0.08));
  EXPECT_FALSE(surfaceCircle(pts, *ls, 0.003, 0.08, 0.01));
}

}  // namespace
}  // namespace modeling
}  // namespace dormant_tree_modeling
