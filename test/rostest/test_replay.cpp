// A recorded tree replayed (replay.test): the views assembled again from the raw scans and
// stage positions, registered and modeled, give the cylinders of the live run within 1 mm.
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <filesystem>

#include "dormant_tree_modeling/io/tree_json.h"

namespace {

using namespace dormant_tree_modeling;

std::string g_bag, g_live, g_replay;

void expectSameCylinder(const modeling::CylinderModel& a, const modeling::CylinderModel& b,
                        const std::string& what) {
  EXPECT_LT((a.center - b.center).norm(), 0.001) << what << " centre";
  EXPECT_LT(std::abs(a.diameter - b.diameter), 0.001) << what << " diameter";
  EXPECT_GT(std::abs(a.axis.dot(b.axis)), std::cos(0.01)) << what << " axis";
}

TEST(Replay, GivesTheCylindersOfTheLiveRun) {
  ASSERT_TRUE(std::filesystem::exists(g_bag))
      << g_bag << " is missing: end_to_end.test records it (run it first)";
  ASSERT_TRUE(std::filesystem::exists(g_live)) << g_live << " is missing (end_to_end.test)";
  std::filesystem::remove(g_replay);
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(360.0);
  while (ros::WallTime::now() < give_up && !std::filesystem::exists(g_replay))
    ros::WallDuration(1.0).sleep();
  ASSERT_TRUE(std::filesystem::exists(g_replay)) << "no model from the replay within 360 s";
  ros::WallDuration(0.5).sleep();
  const modeling::TreeModel live = io::readModelFile(g_live);
  const modeling::TreeModel replay = io::readModelFile(g_replay);
  ASSERT_EQ(replay.trunk.size(), live.trunk.size());
  ASSERT_EQ(replay.primary_branches.size(), live.primary_branches.size());
  for (std::size_t i = 0; i < live.trunk.size(); ++i)
    expectSameCylinder(live.trunk[i], replay.trunk[i], "trunk " + std::to_string(i));
  for (std::size_t i = 0; i < live.primary_branches.size(); ++i)
    expectSameCylinder(live.primary_branches[i].cylinder, replay.primary_branches[i].cylinder,
                       "branch " + std::to_string(i));
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_replay");
  ros::NodeHandle pnh("~");
  g_bag = pnh.param<std::string>("bag", "");
  g_live = pnh.param<std::string>("live_model", "");
  g_replay = pnh.param<std::string>("replay_model", "");
  return RUN_ALL_TESTS();
}
