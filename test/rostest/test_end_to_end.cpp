// The whole system on the virtual platform: virtual_platform -> lms111_driver and
// stage_controller -> scan_assembler -> registration -> tree_modeler, sequenced by the
// acquisition over the paper's 40-view plan with the virtual operator placing the platform.
// The model must match the synthetic tree's truth and every node must report on /diagnostics.
// The bounds leave room for a few of the tree's 30 primaries: the platform runs in real time,
// so which scan lines land in which view, and the registration after it, differ from run to
// run (F1 over runs: 100, 98 and, once on CI, 93 %: two branches missed, two invented), and a
// single tree's F1 moves by a branch with millimetre changes of its cloud. The accuracy
// targets are measured over 12 trees by `make bench`; this test is about the parts working
// together and fails when the model is wrong by more than one branch in ten. The bag and the model
// stay in ~output_dir for the replay test (replay.test).
#include <diagnostic_msgs/DiagnosticArray.h>
#include <dormant_tree_modeling/TreeModel.h>
#include <gtest/gtest.h>
#include <ros/ros.h>

#include <filesystem>
#include <fstream>
#include <map>
#include <mutex>

#include "dormant_tree_modeling/evaluation/matching.h"
#include "dormant_tree_modeling/io/tree_json.h"

namespace {

using namespace dormant_tree_modeling;

std::string g_output_dir;
double g_time_limit = 540.0;

struct DiagnosticsSeen {
  std::mutex mutex;
  std::map<std::string, diagnostic_msgs::DiagnosticStatus> last;  // by status name
  void onArray(const diagnostic_msgs::DiagnosticArrayConstPtr& m) {
    std::lock_guard<std::mutex> lock(mutex);
    for (const auto& s : m->status)
      last[s.name] = s;
  }
};

TEST(EndToEnd, VirtualPlatformToTreeModelMatchesTheTruth) {
  ros::NodeHandle nh;
  DiagnosticsSeen diagnostics;
  ros::Subscriber diag_sub =
      nh.subscribe("/diagnostics", 100, &DiagnosticsSeen::onArray, &diagnostics);
  dormant_tree_modeling::TreeModel::ConstPtr model_msg;
  std::mutex model_mutex;
  ros::Subscriber model_sub = nh.subscribe<dormant_tree_modeling::TreeModel>(
      "/tree_modeler/tree_model", 1, [&](const dormant_tree_modeling::TreeModel::ConstPtr& m) {
        std::lock_guard<std::mutex> lock(model_mutex);
        model_msg = m;
      });
  ros::AsyncSpinner spinner(2);
  spinner.start();

  const std::string model_path = g_output_dir + "/model/model.json";
  const std::string truth_path = g_output_dir + "/truth/truth.json";
  // A model of an earlier run would pass for this one's (the modeler writes it minutes later).
  std::filesystem::remove(model_path);
  std::filesystem::remove(g_output_dir + "/model/turned_down.csv");
  const ros::WallTime give_up = ros::WallTime::now() + ros::WallDuration(g_time_limit);
  while (ros::WallTime::now() < give_up && !std::filesystem::exists(model_path))
    ros::WallDuration(1.0).sleep();
  ASSERT_TRUE(std::filesystem::exists(model_path))
      << "no model.json within " << g_time_limit << " s (see the nodes' output)";
  ros::WallDuration(2.0).sleep();  // a diagnostics period after the model
  {
    std::lock_guard<std::mutex> lock(model_mutex);
    ASSERT_TRUE(model_msg) << "model.json written but no TreeModel received";
    EXPECT_EQ(model_msg->header.frame_id, "tree");
    EXPECT_FALSE(model_msg->trunk.empty());
  }

  // Beside the model: the candidates the branch search turned down, where and why.
  std::ifstream turned_down(g_output_dir + "/model/turned_down.csv");
  std::string header;
  std::getline(turned_down, header);
  EXPECT_EQ(header, "centroid_x,centroid_y,centroid_z,points,reason,budget_spent");

  const modeling::TreeModel model = io::readModelFile(model_path);
  const evaluation::GroundTruth truth = io::readTruthFile(truth_path);
  const evaluation::TreeScore score = evaluation::evaluate(model, truth);
  std::printf("%s", evaluation::formatTable({score}).c_str());
  RecordProperty("f1_percent", static_cast<int>(std::lround(100 * score.f1)));
  RecordProperty("branch_mae_um", static_cast<int>(std::lround(1e6 * score.branch_mae)));
  EXPECT_GE(score.f1, 0.90) << "more than one primary branch in ten missed or invented";
  EXPECT_LE(score.branch_mae, 0.008);
  EXPECT_TRUE(std::filesystem::exists(g_output_dir + "/e2e.bag")) << "the acquisition's bag";

  // Every node reported; none is in error at the end.
  std::lock_guard<std::mutex> lock(diagnostics.mutex);
  for (const char* part : {"virtual platform", "lms111", "stage", "scan assembler", "acquisition",
                           "registration", "tree modeler"}) {
    bool seen = false;
    for (const auto& [name, status] : diagnostics.last) {
      if (name.find(part) == std::string::npos)
        continue;
      seen = true;
      EXPECT_LT(status.level, diagnostic_msgs::DiagnosticStatus::ERROR)
          << name << ": " << status.message;
    }
    EXPECT_TRUE(seen) << "no diagnostics from the " << part;
  }
}

}  // namespace

int main(int argc, char** argv) {
  testing::InitGoogleTest(&argc, argv);
  ros::init(argc, argv, "test_end_to_end");
  ros::NodeHandle pnh("~");
  g_output_dir = pnh.param<std::string>("output_dir", "/tmp/dtm_e2e_rostest");
  g_time_limit = pnh.param("time_limit", g_time_limit);
  return RUN_ALL_TESTS();
}
