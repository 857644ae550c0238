#include <gtest/gtest.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cmath>

#include "dormant_tree_modeling/acquisition/range_image.h"
#include "dormant_tree_modeling/acquisition/view_plan.h"
#include "dormant_tree_modeling/common/error.h"
#include "temp_dir.h"

namespace dormant_tree_modeling {
namespace acquisition {
namespace {

TEST(ViewPlan, ThePapersPlanHasFortyViews) {
  const auto views = makeViewPlan(ViewPlanConfig{});
  ASSERT_EQ(views.size(), 40u);
  EXPECT_EQ(ViewPlanConfig{}.linesPerView(), 200);
  int front = 0;
  for (const auto& v : views)
    front += v.side == "front";
  EXPECT_EQ(front, 20);
  // Five slide positions 10 cm apart per platform position, which stays put meanwhile.
  for (int k = 0; k < 5; ++k) {
    EXPECT_NEAR(views[k].slide, -0.2 + 0.1 * k, 1e-12);
    EXPECT_EQ(views[k].platform_index, 0);
    EXPECT_TRUE(views[k].platform.isApprox(views[0].platform));
  }
  EXPECT_EQ(views[5].platform_index, 1);
  // From the front the platform faces +y, from the back -y; laser heights 1.5 and 4 m.
  EXPECT_NEAR(views[0].platform.linear().col(0).y(), 1.0, 1e-12);
  EXPECT_NEAR(views[39].platform.linear().col(0).y(), -1.0, 1e-12);
  EXPECT_NEAR(views[0].platform.translation().z(), 1.5, 1e-12);
  EXPECT_NEAR(views[19].platform.translation().z(), 4.0, 1e-12);
}

TEST(ViewPlan, YamlOverridesAndErrors) {
  test::TempDir dir;
  const auto plan =
      loadViewPlan(dir.write("p.yaml", "heights_m: [1.2]\nslide_steps: 3\nback: false\n"));
  EXPECT_EQ(makeViewPlan(plan).size(), 6u);  // 1 height x 2 positions x 3 slide steps, front only
  auto code = [](const std::string& path) {
    try {
      loadViewPlan(path);
    } catch (const Error& e) {
      return e.code();
    }
    return ErrorCode::IO_FAILURE;  // not thrown: fails the comparisons below
  };
  EXPECT_EQ(code(dir.write("u.yaml", "heigths: [1]\n")), ErrorCode::PARSE_ERROR);
  EXPECT_EQ(code(dir.write("t.yaml", "slide_steps: many\n")), ErrorCode::PARSE_ERROR);
  EXPECT_EQ(code(dir.write("v.yaml", "standoff_m: 0.2\n")), ErrorCode::INVALID_ARGUMENT);
  EXPECT_EQ(code(dir.file("none.yaml")), ErrorCode::FILE_NOT_FOUND);
}

TEST(RangeImage, SphericalToCartesianOnKnownPoints) {
  double x, y, z;
  sphericalToCartesian(2.0, 0.0, M_PI / 2, x, y, z);  // horizontal, towards the tree
  EXPECT_NEAR(x, 2.0, 1e-12);
  EXPECT_NEAR(y, 0.0, 1e-12);
  EXPECT_NEAR(z, 0.0, 1e-12);
  sphericalToCartesian(1.0, M_PI / 4, 0.0, x, y, z);  // straight down, whatever theta
  EXPECT_NEAR(z, -1.0, 1e-12);
  EXPECT_NEAR(std::hypot(x, y), 0.0, 1e-12);
  sphericalToCartesian(1.0, M_PI / 2, M_PI / 2, x, y, z);  // stage turned 90 deg
  EXPECT_NEAR(y, 1.0, 1e-12);
  RangeImage img;
  img.resize(2, 3);
  img.phi0 = 0.0;
  img.phi_step = M_PI / 2;
  img.theta0 = 0.0;
  img.theta_step = 0.1;
  img.at(0, 1) = 2.0f;  // phi 90 deg
  img.at(1, 2) = 1.0f;  // phi 180 deg: straight up, excluded by phi < pi below
  EXPECT_EQ(img.validCount(), 2u);
  EXPECT_EQ(toCloud(img, 0.0, M_PI)->size(), 1u);
}

}  // namespace
}  // namespace acquisition
}  // namespace dormant_tree_modeling
