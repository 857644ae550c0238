// The acquisition sequencer on the virtual platform: a two-view plan, the operator prompt
// answered, the run finished, the bag read back with every raw topic and both view clouds.
#include <dormant_tree_modeling/AcquisitionProgress.h>
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <rosbag/view.h>
#include <sensor_msgs/LaserScan.h>
#include <std_msgs/String.h>
#include <std_srvs/Trigger.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>
#include <optional>
#include <sstream>

namespace {

std::string g_output_dir;

using Progress = dormant_tree_modeling::AcquisitionProgress;

struct Watcher {
  std::mutex mutex;
  std::string prompt, progress;
  Progress last;
  void onPrompt(const std_msgs::StringConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    prompt = m->data;
  }
  void onProgress(const dormant_tree_modeling::AcquisitionProgressConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    progress = m->text;
    last = *m;
  }
  template <typename T>
  T get(T Watcher::*field) {
    std::lock_guard<std::mutex> lock(mutex);
    return this->*field;
  }
};

TEST(AcquisitionNode, RunsAShortPlanAndWritesABagThatReadsBack) {
  std::filesystem::remove_all(g_output_dir);
  ros::NodeHandle nh;
  Watcher w;
  ros::Subscriber s1 = nh.subscribe("/acquisition/prompt", 10, &Watcher::onPrompt, &w);
  ros::Subscriber s2 = nh.subscribe("/acquisition/progress", 100, &Watcher::onProgress, &w);
  ros::AsyncSpinner spinner(2);
  spinner.start();
  ASSERT_TRUE(ros::service::waitForService("/acquisition/start", 30000));
  // The stage and laser need a moment; the sequencer's first step is the operator's anyway.
  ASSERT_TRUE(ros::service::waitForService("/assembler/scan_assembler/acquire_view", 30000));
  std_srvs::Trigger start;
  ASSERT_TRUE(ros::service::call("/acquisition/start", start));
  ASSERT_TRUE(start.response.success) << start.response.message;

  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(120.0);
  bool answered = false;
  while (ros::WallTime::now() < give_up) {
    if (!answered && w.get(&Watcher::prompt).rfind("Move the platform", 0) == 0) {
      // Give the stage time to home before the first sweep (the sequencer retries too).
      ros::WallDuration(3.0).sleep();
      std_srvs::Trigger in_place;
      ASSERT_TRUE(ros::service::call("/acquisition/platform_in_place", in_place));
      answered = true;
    }
    if (w.get(&Watcher::last).state == Progress::FINISHED)
      break;
    ros::WallDuration(0.1).sleep();
  }
  const std::string progress = w.get(&Watcher::progress);
  std::printf("[ INFO ] %s\n", progress.c_str());
  ASSERT_EQ(progress.rfind("finished: 2 of 2 planned views acquired", 0), 0u) << progress;
  const Progress end = w.get(&Watcher::last);
  EXPECT_EQ(end.state, Progress::FINISHED);
  EXPECT_EQ(end.done, 2);
  EXPECT_EQ(end.failed, 0);
  EXPECT_EQ(end.planned, 2);
  EXPECT_EQ(end.view, 2) << "the last view in hand";

  std::ifstream report(g_output_dir + "/virtual_tree_report.md");
  ASSERT_TRUE(report.good());
  std::stringstream text;
  text << report.rdbuf();
  EXPECT_NE(text.str().find("| 2 | ok |"), std::string::npos) << text.str();

  rosbag::Bag bag;
  ASSERT_NO_THROW(bag.open(g_output_dir + "/virtual_tree.bag", rosbag::bagmode::Read));
  std::map<std::string, std::size_t> counts;
  rosbag::View view(bag);
  for (const auto& m : view)
    ++counts[m.getTopic()];
  for (const auto& [topic, n] : counts)
    std::printf("[ INFO ] %s: %zu messages\n", topic.c_str(), n);
  EXPECT_GT(counts["/lms111/scan"], 300u);  // two 8 s sweeps at 25 Hz and the moves between
  EXPECT_GT(counts["/stage/joint_states"], 500u);
  EXPECT_GT(counts["/tf"], 0u);
  EXPECT_GT(counts["/tf_static"], 0u);
  EXPECT_EQ(counts["/assembler/view_cloud"], 2u);
  // The bag ends with the plan's end, typed, so a replay knows how many views to wait for.
  rosbag::View ends(bag, rosbag::TopicQuery("/acquisition/progress"));
  std::optional<Progress> recorded_end;
  for (const auto& m : ends) {
    if (const auto p = m.instantiate<Progress>())
      recorded_end = *p;
  }
  ASSERT_TRUE(recorded_end);
  EXPECT_EQ(recorded_end->state, Progress::FINISHED);
  EXPECT_EQ(recorded_end->done, 2);
  // The recorded scans deserialize as LaserScans.
  rosbag::View scans(bag, rosbag::TopicQuery("/lms111/scan"));
  const auto first = scans.begin()->instantiate<sensor_msgs::LaserScan>();
  ASSERT_TRUE(first);
  EXPECT_EQ(first->ranges.size(), 1081u);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_acquisition_node");
  ros::NodeHandle pnh("~");
  g_output_dir = pnh.param<std::string>("output_dir", "/tmp/dtm_acquisition_rostest");
  return RUN_ALL_TESTS();
}
