#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <sensor_msgs/point_cloud2_iterator.h>

namespace {

sensor_msgs::PointCloud2ConstPtr waitForCloud() {
  ros::NodeHandle nh;
  return ros::topic::waitForMessage<sensor_msgs::PointCloud2>("cloud", nh, ros::Duration(20.0));
}

TEST(CloudFilePublisher, PublishesTheFiniteFilePointsLatched) {
  const auto msg = waitForCloud();
  ASSERT_TRUE(msg) << "no cloud on /cloud within 20 s";
  EXPECT_EQ(msg->header.frame_id, "test_frame");
  ASSERT_EQ(msg->width * msg->height, 3u);  // the NaN line is dropped
  sensor_msgs::PointCloud2ConstIterator<float> x(*msg, "x"), y(*msg, "y"), z(*msg, "z");
  ++x;
  ++y;
  ++z;
  EXPECT_FLOAT_EQ(*x, 1.0f);
  EXPECT_FLOAT_EQ(*y, 2.0f);
  EXPECT_FLOAT_EQ(*z, 3.0f);
}

TEST(CloudFilePublisher, LateSubscriberStillGetsTheCloud) {
  ros::Duration(0.2).sleep();
  const auto msg = waitForCloud();
  ASSERT_TRUE(msg);
  EXPECT_EQ(msg->width * msg->height, 3u);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_cloud_file_publisher");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}
