#include <dormant_tree_modeling/TreeModel.h>
#include <gtest/gtest.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_srvs/Trigger.h>
#include <visualization_msgs/MarkerArray.h>

#include <filesystem>

#include "synthetic_tree.h"

namespace {

using namespace dormant_tree_modeling;

TEST(TreeModelerNode, PublishesModelMarkersAndSegments) {
  ros::NodeHandle nh;
  ros::Publisher pub = nh.advertise<sensor_msgs::PointCloud2>("tree_cloud", 1, true);
  pub.publish(test::syntheticTree("tree"));
  const auto model = ros::topic::waitForMessage<dormant_tree_modeling::TreeModel>(
      "tree_model", nh, ros::Duration(90.0));
  ASSERT_TRUE(model) << "no TreeModel within 90 s";
  EXPECT_EQ(model->header.frame_id, "tree");
  ASSERT_FALSE(model->trunk.empty());
  EXPECT_GT(model->primary_branches.size(), 5u);
  EXPECT_EQ(model->measurements.size(), model->primary_branches.size());
  for (const auto& c : model->trunk) {
    EXPECT_EQ(c.role, dormant_tree_modeling::Cylinder::TRUNK);
    EXPECT_GT(c.radius, 0.005);
    EXPECT_LT(c.radius, 0.06);
  }
  for (const auto& b : model->primary_branches)
    EXPECT_GE(b.parent_id, 0);
  const auto markers = ros::topic::waitForMessage<visualization_msgs::MarkerArray>(
      "markers", nh, ros::Duration(5.0));
  ASSERT_TRUE(markers);
  // DELETEALL, then a cylinder and a label for every trunk segment and branch.
  EXPECT_EQ(markers->markers.size(),
            1 + 2 * (model->trunk.size() + model->primary_branches.size()));
  // A branch whose radius was corrected to its floor says so (so may one above it whose
  // reading thinner branches give too), with the range of diameters it may have; its cylinder
  // is grey and its label gives that range.
  for (std::size_t i = 0; i < model->measurements.size(); ++i) {
    const auto& m = model->measurements[i];
    if (m.diameter <= 0.004 + 1e-9) {
      EXPECT_FALSE(m.diameter_resolved) << "branch " << i;
    }
    EXPECT_LE(m.diameter_min, m.diameter + 1e-12) << "branch " << i;
    EXPECT_GE(m.diameter_max, m.diameter - 1e-12) << "branch " << i;
    EXPECT_DOUBLE_EQ(m.diameter_resolved ? m.diameter : 0.004, m.diameter_min) << "branch " << i;
    const std::size_t marker = 1 + 2 * (model->trunk.size() + i);
    if (marker + 1 < markers->markers.size()) {
      const auto& color = markers->markers[marker].color;
      EXPECT_EQ(!m.diameter_resolved, color.r == color.g && color.g == color.b) << "branch " << i;
      const std::string& text = markers->markers[marker + 1].text;
      EXPECT_EQ(!m.diameter_resolved, text.find('-') != std::string::npos) << text;
    }
  }
  const auto segments =
      ros::topic::waitForMessage<sensor_msgs::PointCloud2>("segments", nh, ros::Duration(5.0));
  ASSERT_TRUE(segments);
  EXPECT_GT(segments->width * segments->height, 1000u);
}

TEST(TreeModelerNode, ServiceRemodelsTheLastCloud) {
  ros::NodeHandle nh;
  ASSERT_TRUE(ros::service::waitForService("tree_modeler/model_tree", ros::Duration(10.0)));
  std_srvs::Trigger srv;
  ASSERT_TRUE(ros::service::call("tree_modeler/model_tree", srv));
  EXPECT_TRUE(srv.response.success) << srv.response.message;
  EXPECT_NE(srv.response.message.find("trunk cylinders"), std::string::npos)
      << srv.response.message;
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_tree_modeler_node");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}
