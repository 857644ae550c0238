// rviz with the shipped config, on a virtual display, draws the cylinders of a model: a
// synthetic tree is modeled by the tree_modeler, scripts/rviz_screenshot photographs rviz, and
// the picture must hold brown (trunk) and green or red (branch) pixels in the 3-D view.
#include <dormant_tree_modeling/TreeModel.h>
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <cstdlib>
#include <filesystem>
#include <string>

#define STB_IMAGE_IMPLEMENTATION
#include <stb/stb_image.h>

#include "synthetic_tree.h"

namespace {

using namespace dormant_tree_modeling;

struct ColourCounts {
  long brown = 0, green = 0, red = 0, other = 0;
};

// Marker colours (model_messages.cpp) under rviz's lighting: hue families, not exact values.
ColourCounts countColours(const std::string& png, int min_x) {
  int w = 0, h = 0, n = 0;
  unsigned char* data = stbi_load(png.c_str(), &w, &h, &n, 3);
  if (!data)
    throw std::runtime_error("cannot read " + png);
  ColourCounts c;
  for (int y = 0; y < h; ++y) {
    for (int x = min_x; x < w; ++x) {
      const unsigned char* p = data + 3 * (y * w + x);
      const int r = p[0], g = p[1], b = p[2];
      if (g > 90 && g > r + 40 && g > b + 40)
        ++c.green;
      else if (r > 150 && g < 90 && b < 90)
        ++c.red;
      else if (r > 80 && r > g + 25 && g > b + 15)
        ++c.brown;
      else if (!(r == 48 && g == 48 && b == 48))
        ++c.other;
    }
  }
  stbi_image_free(data);
  return c;
}

TEST(Rviz, DrawsTheCylindersOfAModel) {
  ros::NodeHandle nh;
  ros::Publisher pub = nh.advertise<sensor_msgs::PointCloud2>("/registration/tree_cloud", 1, true);
  pub.publish(test::syntheticTree("orchard"));
  const auto model = ros::topic::waitForMessage<dormant_tree_modeling::TreeModel>(
      "/tree_modeler/tree_model", nh, ros::Duration(120.0));
  ASSERT_TRUE(model) << "no TreeModel within 120 s";
  ASSERT_FALSE(model->trunk.empty());
  ASSERT_FALSE(model->primary_branches.empty());

  const std::string shot = "/tmp/dtm_rviz_rostest/rviz.png";
  std::filesystem::remove(shot);
  const std::string cmd = std::string(DTM_SOURCE_DIR) + "/scripts/rviz_screenshot " + shot +
                          " --wait 8 > /tmp/dtm_rviz_rostest.log 2>&1";
  const int rc = std::system(cmd.c_str());
  ASSERT_EQ(rc, 0) << cmd << " failed; see /tmp/dtm_rviz_rostest.log";
  // The 3-D view is right of the displays panel (about 360 of 1280 px).
  const ColourCounts c = countColours(shot, 400);
  RecordProperty("brown_pixels", static_cast<int>(c.brown));
  RecordProperty("green_pixels", static_cast<int>(c.green));
  EXPECT_GT(c.brown, 200) << "trunk cylinders not drawn";
  EXPECT_GT(c.green + c.red, 200) << "branch cylinders not drawn";
  EXPECT_GT(c.other, 5000) << "the point clouds are not drawn";
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_rviz_screenshot");
  return RUN_ALL_TESTS();
}
