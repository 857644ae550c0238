// The registration node: views arriving as the scan assembler publishes them (platform frame,
// the platform's hinted pose on tf) are registered on ~register into one tree cloud.
#include <dormant_tree_modeling/AcquisitionProgress.h>
#include <geometry_msgs/PoseArray.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/Int32.h>
#include <std_msgs/String.h>
#include <std_srvs/Trigger.h>
#include <tf2_eigen/tf2_eigen.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/static_transform_broadcaster.h>

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <filesystem>
#include <mutex>
#include <string>
#include <vector>

#include "dormant_tree_modeling/registration/view_folder.h"
#include "dormant_tree_modeling/ros/conversions.h"
#include "dormant_tree_modeling/ros/registration_node.h"
#include "dormant_tree_modeling/ros/tf_feed.h"
#include "dormant_tree_modeling/simulation/dataset.h"

namespace {

using namespace dormant_tree_modeling;

bool callTrigger(const std::string& service, std::string& message) {
  std_srvs::Trigger t;
  EXPECT_TRUE(ros::service::waitForService(service, ros::Duration(10.0)));
  EXPECT_TRUE(ros::service::call(service, t));
  message = t.response.message;
  return t.response.success;
}

// Four platform positions (two per side), two slide positions each, guesses 0.5 m / 20 deg
// off: the views as the scan assembler would publish them. Built once.
const registration::ViewFolder& dataset() {
  static const registration::ViewFolder folder = [] {
    const auto dir = std::filesystem::temp_directory_path() /
                     ("dtm_registration_rostest_" + std::to_string(getpid()));
    simulation::DatasetConfig o;
    o.seed = 5;
    o.sensor.range_noise_sigma = 0.006;
    o.plan.heights_m = {1.5};
    o.plan.slide_steps = 2;
    o.plan.slide_step_m = 0.2;
    simulation::writeDataset(o, dir.string());
    registration::ViewFolder f = registration::readViewFolder(dir.string());
    std::filesystem::remove_all(dir);
    return f;
  }();
  return folder;
}

/// Publishes views [first, last) of the dataset, each platform position's hint on tf first.
void publishViews(ros::Publisher& pub, tf2_ros::StaticTransformBroadcaster& hints,
                  std::size_t first, std::size_t last) {
  const auto& folder = dataset();
  int station = first > 0 ? folder.views[first - 1].station : -1;
  for (std::size_t i = first; i < last; ++i) {
    const auto& v = folder.views[i];
    if (v.station != station) {
      // The operator moved the platform: a new hint.
      station = v.station;
      geometry_msgs::TransformStamped t = tf2::eigenToTransform(*v.station_hint);
      t.header.frame_id = "orchard";
      t.header.stamp = ros::Time::now();
      t.child_frame_id = "platform";
      hints.sendTransform(t);
      ros::Duration(0.5).sleep();
    }
    Cloud cloud;
    for (const auto& p : v.points) {
      const Eigen::Vector3d q = v.in_station * p;  // into the platform frame
      cloud.push_back(pcl::PointXYZ(q.x(), q.y(), q.z()));
    }
    pub.publish(ros_layer::toMsg(cloud, "platform", ros::Time::now()));
    ros::Duration(0.3).sleep();
  }
}

TEST(RegistrationNode, RegistersTheViewsOfTwoPlatformPositionsPerSide) {
  ros::NodeHandle nh;
  std::string message;
  EXPECT_FALSE(callTrigger("/registration/register", message)) << "nothing collected yet";
  EXPECT_NE(message.find("no views"), std::string::npos) << message;

  const registration::ViewFolder& folder = dataset();
  ASSERT_EQ(folder.views.size(), 8u);

  ros::Publisher pub = nh.advertise<sensor_msgs::PointCloud2>("view_cloud", 10);
  tf2_ros::StaticTransformBroadcaster hints;
  ros::Duration(1.0).sleep();  // the node connects
  publishViews(pub, hints, 0, folder.views.size());
  ros::Duration(1.0).sleep();
  EXPECT_TRUE(callTrigger("/registration/register", message)) << message;

  const auto tree = ros::topic::waitForMessage<sensor_msgs::PointCloud2>("/registration/tree_cloud",
                                                                         nh, ros::Duration(60.0));
  ASSERT_TRUE(tree) << "no tree_cloud within 60 s";
  EXPECT_EQ(tree->header.frame_id, "tree");
  std::size_t total = 0;
  for (const auto& v : folder.views)
    total += v.points.size();
  EXPECT_EQ(static_cast<std::size_t>(tree->width) * tree->height, total)
      << "every view registered and merged";

  const auto poses = ros::topic::waitForMessage<geometry_msgs::PoseArray>(
      "/registration/view_poses", nh, ros::Duration(5.0));
  ASSERT_TRUE(poses);
  ASSERT_EQ(poses->poses.size(), folder.views.size());
  // Against the truth: view i's platform frame in the first view's.
  const Eigen::Isometry3d world_to_first = folder.true_poses[0]->inverse();
  double worst_mm = 0;
  for (std::size_t i = 0; i < folder.views.size(); ++i) {
    Eigen::Isometry3d got;
    tf2::fromMsg(poses->poses[i], got);
    const Eigen::Isometry3d truth =
        world_to_first * *folder.true_poses[i] * folder.views[i].in_station.inverse();
    // Error at the tree, 1.5 m ahead and 1.5 m up from the platform frame's origin.
    const Eigen::Vector3d at_tree(1.5, 0.0, 0.0);
    worst_mm = std::max(worst_mm, (got * at_tree - truth * at_tree).norm() * 1000);
  }
  std::printf("[ INFO ] 8 views, 4 platform positions: worst error at the tree %.1f mm\n",
              worst_mm);
  EXPECT_LT(worst_mm, 20.0);

  const auto report =
      ros::topic::waitForMessage<std_msgs::String>("/registration/report", nh, ros::Duration(5.0));
  ASSERT_TRUE(report);
  EXPECT_NE(report->data.find("8 of 8 views registered"), std::string::npos) << report->data;

  // The files: one folder per registration under ~output_dir.
  std::string out;
  ASSERT_TRUE(ros::param::get("/registration/output_dir", out));
  bool written = false;
  for (int i = 0; i < 50 && !written; ++i) {
    ros::Duration(0.1).sleep();
    if (std::filesystem::exists(out)) {
      for (const auto& d : std::filesystem::directory_iterator(out))
        written = written || std::filesystem::exists(d.path() / "registration.md");
    }
  }
  EXPECT_TRUE(written) << "no registration.md under " << out;
  std::filesystem::remove_all(out);

  // The views went to that registration: a new tree starts empty.
  EXPECT_FALSE(callTrigger("/registration/register", message));
}

TEST(RegistrationNode, WaitsForTheViewsThePlansEndNames) {
  // A replay: the plan's end arrives while the last sweep is still being assembled.
  ros::NodeHandle nh;
  ros::Publisher pub = nh.advertise<sensor_msgs::PointCloud2>("view_cloud", 10);
  ros::Publisher progress =
      nh.advertise<dormant_tree_modeling::AcquisitionProgress>("/acquisition/progress", 10);
  tf2_ros::StaticTransformBroadcaster hints;
  // The report is latched: the first test's comes first, this test's after it.
  std::mutex mutex;
  std::vector<std::string> reports;
  ros::Subscriber sub = nh.subscribe<std_msgs::String>("/registration/report", 5,
                                                       [&](const std_msgs::StringConstPtr& m) {
                                                         std::lock_guard<std::mutex> lock(mutex);
                                                         reports.push_back(m->data);
                                                       });
  ros::Duration(1.0).sleep();
  std::size_t before = 0;
  {
    std::lock_guard<std::mutex> lock(mutex);
    before = reports.size();
  }
  publishViews(pub, hints, 0, 7);
  dormant_tree_modeling::AcquisitionProgress finished;
  finished.state = dormant_tree_modeling::AcquisitionProgress::FINISHED;
  finished.view = finished.done = finished.planned = 8;
  finished.text = "finished: 8 of 8 planned views acquired, 40 s of scanning.";
  progress.publish(finished);
  ros::Duration(1.0).sleep();
  publishViews(pub, hints, 7, 8);
  std::string report;
  for (int i = 0; i < 600 && report.empty(); ++i) {
    ros::Duration(0.1).sleep();
    std::lock_guard<std::mutex> lock(mutex);
    if (reports.size() > before)
      report = reports.back();
  }
  ASSERT_FALSE(report.empty()) << "no registration within 60 s of the plan's end";
  EXPECT_NE(report.find("8 of 8 views registered"), std::string::npos) << report;
}

/// A message as a subscriber of any type receives it.
template <typename M>
void shapeOf(const M& message, topic_tools::ShapeShifter& shape) {
  const std::uint32_t size = ros::serialization::serializationLength(message);
  std::vector<std::uint8_t> buffer(size);
  ros::serialization::OStream out(buffer.data(), size);
  ros::serialization::serialize(out, message);
  shape.morph(ros::message_traits::md5sum<M>(), ros::message_traits::datatype<M>(),
              ros::message_traits::definition<M>(), "");
  ros::serialization::IStream in(buffer.data(), size);
  shape.read(in);
}

TEST(PlanEnd, ReadsTheTypedProgressAndTheTextOfOlderBags) {
  using dormant_tree_modeling::AcquisitionProgress;
  topic_tools::ShapeShifter shape;
  AcquisitionProgress p;
  p.state = AcquisitionProgress::RUNNING;
  p.done = 3;
  shapeOf(p, shape);
  EXPECT_FALSE(ros_layer::planEnd(shape)) << "a running plan has not ended";
  p.state = AcquisitionProgress::FINISHED;
  p.done = 7;
  shapeOf(p, shape);
  ASSERT_TRUE(ros_layer::planEnd(shape));
  EXPECT_EQ(ros_layer::planEnd(shape)->views, 7);

  std_msgs::String text;
  text.data = "finished: 38 of 40 planned views acquired, 2412 s of scanning.";
  shapeOf(text, shape);
  ASSERT_TRUE(ros_layer::planEnd(shape)) << "bags recorded before the progress was typed";
  EXPECT_EQ(ros_layer::planEnd(shape)->views, 38);
  text.data = "view 3 of 40";
  shapeOf(text, shape);
  EXPECT_FALSE(ros_layer::planEnd(shape));

  std_msgs::Int32 other;
  shapeOf(other, shape);
  EXPECT_FALSE(ros_layer::planEnd(shape)) << "another type is no plan's end";
}

TEST(FrameKnown, NamesEveryFrameOfTheTreeRootsIncludedAndNothingElse) {
  tf2_ros::Buffer buffer;
  EXPECT_FALSE(ros_layer::frameKnown(buffer, "orchard")) << "an empty buffer knows no frame";
  geometry_msgs::TransformStamped t;
  t.header.stamp = ros::Time(10.0);
  t.header.frame_id = "orchard";
  t.child_frame_id = "platform";
  t.transform.rotation.w = 1.0;
  buffer.setTransform(t, "test", true);
  t.header.frame_id = "platform";
  t.child_frame_id = "laser";
  buffer.setTransform(t, "test", false);
  EXPECT_TRUE(ros_layer::frameKnown(buffer, "orchard")) << "the root: only ever a parent";
  EXPECT_TRUE(ros_layer::frameKnown(buffer, "platform"));
  EXPECT_TRUE(ros_layer::frameKnown(buffer, "laser"));
  EXPECT_FALSE(ros_layer::frameKnown(buffer, "tree"));
  EXPECT_FALSE(ros_layer::frameKnown(buffer, "las"));
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_registration_node");
  ros::AsyncSpinner spinner(1);
  spinner.start();
  return RUN_ALL_TESTS();
}
