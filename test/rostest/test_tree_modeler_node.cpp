#include <dormant_tree_modeling/TreeModel.h>
#include <gtest/gtest.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_srvs/Trigger.h>
#include <visualization_msgs/MarkerArray.h>

#include <filesystem>

#include "dormant_tree_modeling/ros/model_messages.h"
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

TEST(TreeModelerNode, ABranchNotMeasuredIsGreyAndLabelledWithTheDiametersItMayHave) {
  // The synthetic tree above has every diameter measured: one trunk cylinder, one branch
  // measured at 21 mm and one not measured (4 to 9.1 mm).
  modeling::TreeModel model;
  modeling::CylinderModel trunk;
  trunk.diameter = 0.04;
  trunk.length = 1.0;
  model.trunk.push_back(trunk);
  for (int k = 0; k < 2; ++k) {
    modeling::PrimaryBranch b;
    b.cylinder.id = 1 + k;
    b.cylinder.axis = Eigen::Vector3d::UnitX();
    b.cylinder.length = 0.3;
    b.cylinder.diameter = k == 0 ? 0.021 : 0.006;
    b.trunk_segment = 0;
    b.measurement.diameter_resolved = k == 0;
    b.measurement.diameter_min = k == 0 ? 0.021 : 0.004;
    b.measurement.diameter_max = k == 0 ? 0.021 : 0.0091;
    model.primary_branches.push_back(b);
  }
  std_msgs::Header header;
  header.frame_id = "tree";
  const auto msg = ros_layer::toMsg(model, header);
  ASSERT_EQ(msg.measurements.size(), 2u);
  EXPECT_DOUBLE_EQ(msg.measurements[0].diameter_min, 0.021);
  EXPECT_DOUBLE_EQ(msg.measurements[0].diameter_max, 0.021);
  EXPECT_FALSE(msg.measurements[1].diameter_resolved);
  EXPECT_DOUBLE_EQ(msg.measurements[1].diameter_min, 0.004);
  EXPECT_DOUBLE_EQ(msg.measurements[1].diameter_max, 0.0091);
  // DELETEALL; the trunk's cylinder and label; each branch's cylinder and label.
  const auto markers = ros_layer::toMarkers(model, header);
  ASSERT_EQ(markers.markers.size(), 7u);
  EXPECT_EQ(markers.markers[2].text, "4.0 cm");
  EXPECT_EQ(markers.markers[4].text, "2.1 cm");
  EXPECT_EQ(markers.markers[6].text, "0.4-0.9 cm");
  const auto grey = [](const std_msgs::ColorRGBA& c) { return c.r == c.g && c.g == c.b; };
  EXPECT_FALSE(grey(markers.markers[3].color));
  EXPECT_TRUE(grey(markers.markers[5].color));
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_tree_modeler_node");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}
