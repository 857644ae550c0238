// scripts/replay_bag (replay_bag.test) ends every replay with a status: a bag cut off mid-file
// cannot be played (5, at once); the same bag reindexed gives a model of the views it holds
// and says the input was incomplete (4).
#include <gtest/gtest.h>
#include <ros/ros.h>
#include <sys/wait.h>

#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <string>

namespace {

namespace fs = std::filesystem;

std::string g_bag;

/// A fresh folder for one replay.
fs::path workDir(const std::string& name) {
  const fs::path dir = fs::temp_directory_path() / ("dtm_replay_bag_" + name);
  fs::remove_all(dir);
  fs::create_directories(dir);
  return dir;
}

/// The first `bytes` of the recorded bag: what a disk that filled up mid-recording leaves.
void cutBag(const fs::path& to, std::size_t bytes) {
  std::ifstream in(g_bag, std::ios::binary);
  std::string head(bytes, '\0');
  in.read(head.data(), static_cast<std::streamsize>(bytes));
  ASSERT_EQ(static_cast<std::size_t>(in.gcount()), bytes) << g_bag << " is shorter";
  std::ofstream(to, std::ios::binary).write(head.data(), static_cast<std::streamsize>(bytes));
}

/// Runs a shell command; its exit status, or -1 when it did not exit.
int run(const std::string& command) {
  const int status = std::system(command.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

/// scripts/replay_bag on a master of its own (the test's master runs this test), logs in dir.
int replayBag(const fs::path& bag, const fs::path& dir, int port) {
  return run("ROS_MASTER_URI=http://127.0.0.1:" + std::to_string(port) +
             " ROS_HOME=" + (dir / "ros_home").string() +
             " timeout 300 " DTM_SOURCE_DIR "/scripts/replay_bag " + bag.string() + " " +
             (dir / "out").string() + " rate:=2 > " + (dir / "replay.log").string() + " 2>&1");
}

TEST(ReplayBag, ACutBagEndsWithAStatusAndAModelOfWhatItHolds) {
  ASSERT_TRUE(fs::exists(g_bag)) << g_bag << " is missing: end_to_end.test records it";
  const std::size_t cut = fs::file_size(g_bag) * 55 / 100;

  const fs::path raw = workDir("raw");
  cutBag(raw / "cut.bag", cut);
  const ros::WallTime start = ros::WallTime::now();
  EXPECT_EQ(replayBag(raw / "cut.bag", raw, 11861), 5) << "see " << raw / "replay.log";
  EXPECT_LT((ros::WallTime::now() - start).toSec(), 60.0) << "an unplayable bag ends at once";
  EXPECT_FALSE(fs::exists(raw / "out/model/model.json"));

  const fs::path reindexed = workDir("reindexed");
  cutBag(reindexed / "cut.bag", cut);
  ASSERT_EQ(run("cd " + reindexed.string() + " && rosbag reindex cut.bag > reindex.log 2>&1"), 0);
  EXPECT_EQ(replayBag(reindexed / "cut.bag", reindexed, 11862), 4)
      << "see " << reindexed / "replay.log";
  EXPECT_TRUE(fs::exists(reindexed / "out/model/model.json")) << "a model of the views it holds";
  nlohmann::json input;
  for (const auto& entry : fs::recursive_directory_iterator(reindexed / "out/registration")) {
    if (entry.path().filename() == "registration.json")
      input = nlohmann::json::parse(std::ifstream(entry.path())).at("input");
  }
  ASSERT_FALSE(input.is_null()) << "no registration.json with an input record";
  EXPECT_EQ(input.at("ended_by"), "input_quiet");
  EXPECT_FALSE(input.at("complete").get<bool>());
  EXPECT_GT(input.at("views_received").get<int>(), 10);
  EXPECT_LT(input.at("views_received").get<int>(), 40);
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_replay_bag");
  ros::NodeHandle pnh("~");
  g_bag = pnh.param<std::string>("bag", "");
  return RUN_ALL_TESTS();
}
