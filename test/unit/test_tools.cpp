#include <gtest/gtest.h>
#include <sys/wait.h>

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "dormant_tree_modeling/emulation/session_replay.h"
#include "dormant_tree_modeling/evaluation/ground_truth.h"
#include "dormant_tree_modeling/io/cylinder_csv.h"
#include "dormant_tree_modeling/io/tree_json.h"
#include "dormant_tree_modeling/lms111/capture.h"
#include "temp_dir.h"

namespace dormant_tree_modeling {
namespace {

/// Runs a built tool with arguments, returns its exit status; stdout+stderr into `output`.
int run(const std::string& tool, const std::string& args, std::string* output = nullptr) {
  const std::string log =
      (std::filesystem::temp_directory_path() / ("dtm_tool_" + std::to_string(getpid()))).string();
  const std::string cmd =
      std::string(DTM_TOOL_DIR) + "/" + tool + " " + args + " > " + log + " 2>&1";
  const int status = std::system(cmd.c_str());
  if (output) {
    std::ifstream f(log);
    std::stringstream ss;
    ss << f.rdbuf();
    *output = ss.str();
  }
  std::remove(log.c_str());
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

TEST(CalibrateDiametersTool, FromARigScanToAModelThatNamesIt) {
  test::TempDir dir;
  std::string out;
  EXPECT_EQ(run("calibrate_diameters", "--scan x.pcd", &out), 2) << out;  // no --truth, no -o
  EXPECT_EQ(run("calibrate_diameters",
                "--scan " + dir.write("empty.xyz", "# none\n") + " --truth " +
                    dir.file("absent.json") + " -o " + dir.file("c.yaml"),
                &out),
            3)
      << out;
  ASSERT_EQ(
      run("synth_tree",
          "--preset calibration_rig --noise-mm 6 --no-view-files --out " + dir.file("rig"), &out),
      0)
      << out;
  ASSERT_EQ(run("calibrate_diameters",
                "--scan " + dir.file("rig/target.pcd") + " --truth " + dir.file("rig/truth.json") +
                    " --name unit7 -o " + dir.file("c.yaml"),
                &out),
            0)
      << out;
  EXPECT_NE(out.find("covers: trunk radius 8.0-100.0 mm"), std::string::npos) << out;
  ASSERT_EQ(run("tree_model",
                dir.file("rig/target.pcd") + " -o " + dir.file("m.json") + " --calibration " +
                    dir.file("c.yaml"),
                &out),
            0)
      << out;
  const auto model = io::readModelFile(dir.file("m.json"));
  EXPECT_EQ(model.correction.calibration, "unit7");
  EXPECT_EQ(model.correction.calibration_hash.size(), 16u);
  EXPECT_EQ(run("tree_model",
                dir.file("rig/target.pcd") + " -o " + dir.file("m.json") + " --calibration " +
                    dir.file("absent.yaml"),
                &out),
            3)
      << out;
}

TEST(TreeModelTool, ExitCodesAreDistinctAndDocumented) {
  test::TempDir dir;
  std::string out;
  EXPECT_EQ(run("tree_model", "", &out), 2) << out;  // usage
  EXPECT_EQ(run("tree_model", dir.file("absent.pcd") + " -o " + dir.file("m.json"), &out), 3)
      << out;
  EXPECT_NE(out.find("file_not_found"), std::string::npos) << out;
  EXPECT_EQ(
      run("tree_model", dir.write("bad.xyz", "1 2 three\n") + " -o " + dir.file("m.json"), &out), 3)
      << out;
  EXPECT_EQ(
      run("tree_model", dir.write("empty.xyz", "# nothing\n") + " -o " + dir.file("m.json"), &out),
      4)
      << out;
  // A file the system will not read (any process's read of its own /proc/self/mem at 0 fails,
  // even as root, where permissions would not): unreadable input, not an output failure (7).
  std::filesystem::create_symlink("/proc/self/mem", dir.file("unreadable.xyz"));
  EXPECT_EQ(run("tree_model", dir.file("unreadable.xyz") + " -o " + dir.file("m.json"), &out), 3)
      << out;
  EXPECT_NE(out.find("read error"), std::string::npos) << out;
  std::string plane;
  for (int i = 0; i < 60; ++i) {
    for (int k = 0; k < 60; ++k)
      plane += std::to_string(0.01 * i) + " " + std::to_string(0.01 * k) + " 1.0\n";
  }
  EXPECT_EQ(run("tree_model", dir.write("plane.xyz", plane) + " -o " + dir.file("m.json"), &out), 5)
      << out;
  EXPECT_NE(out.find("no_trunk"), std::string::npos) << out;
  EXPECT_EQ(run("tree_model",
                dir.file("plane.xyz") + " -o " + dir.file("m.json") + " -p " +
                    dir.write("p.yaml", "graph:\n  psi_t_deg: 500\n"),
                &out),
            6)
      << out;
  // Exactly one line on stderr for a failure.
  EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
  EXPECT_FALSE(std::filesystem::exists(dir.file("m.json")));
}

TEST(TreeModelTool, ModelsARealCloudAndEvaluateModelScoresIt) {
  const std::string tree = std::string(DTM_SHARED_DATA_DIR) + "/real/adtree_tree1.xyz";
  if (!std::filesystem::exists(tree))
    GTEST_SKIP() << "../shared/data not present";
  test::TempDir dir;
  std::string out;
  ASSERT_EQ(run("tree_model",
                tree + " --output " + dir.file("m.json") + " --csv " + dir.file("c.csv") +
                    " --turned-down " + dir.file("t.csv"),
                &out),
            0)
      << out;
  const auto model = io::readModelFile(dir.file("m.json"));
  ASSERT_FALSE(model.trunk.empty());
  // Survey-style input coordinates come back as given (tree1 sits at y ~ 18 m).
  EXPECT_GT(model.trunk.front().center.y(), 17.0);
  std::ifstream csv(dir.file("c.csv"));
  std::string header;
  std::getline(csv, header);
  EXPECT_EQ(header.rfind("role,id,parent_id,center_x", 0), 0u);
  // The turned-down file is written with its header (this tree's search turns none down).
  std::ifstream turned_down(dir.file("t.csv"));
  std::getline(turned_down, header);
  EXPECT_EQ(header, "centroid_x,centroid_y,centroid_z,points,reason,budget_spent");
  // A truth that is the model's own trunk: the evaluation runs and prints a row.
  evaluation::GroundTruth truth;
  for (const auto& c : model.trunk) {
    truth.trunk.points.push_back(c.center - 0.5 * c.length * c.axis);
    truth.trunk.diameters.push_back(c.diameter);
  }
  truth.trunk.points.push_back(model.trunk.back().center +
                               0.5 * model.trunk.back().length * model.trunk.back().axis);
  truth.trunk.diameters.push_back(model.trunk.back().diameter);
  io::writeTextFile(dir.file("t.json"), io::truthToJson(truth));
  ASSERT_EQ(
      run("evaluate_model",
          "--model " + dir.file("m.json") + " --truth " + dir.file("t.json") + " --json", &out),
      0)
      << out;
  EXPECT_NE(out.find("\"coverage\""), std::string::npos) << out;
  EXPECT_EQ(run("evaluate_model", "--model " + dir.file("m.json"), &out), 2) << out;
}

TEST(CylinderCsv, OneRowPerCylinderWithBranchColumns) {
  modeling::TreeModel m;
  modeling::CylinderModel t;
  t.id = 0;
  t.diameter = 0.05;
  m.trunk.push_back(t);
  modeling::PrimaryBranch b;
  b.cylinder.id = 1;
  b.cylinder.diameter = 0.02;
  b.trunk_segment = 0;
  b.measurement.angle_to_trunk = M_PI / 2;
  b.measurement.diameter_ratio = 0.4;
  b.measurement.diameter_resolved = false;
  b.measurement.diameter_min = 0.004;
  b.measurement.diameter_max = 0.0215;
  m.primary_branches.push_back(b);
  const std::string csv = io::cylindersToCsv(m, Eigen::Vector3d(100, 0, 0));
  std::istringstream lines(csv);
  std::string header, trunk, branch;
  std::getline(lines, header);
  std::getline(lines, trunk);
  std::getline(lines, branch);
  EXPECT_EQ(std::count(header.begin(), header.end(), ','),
            std::count(trunk.begin(), trunk.end(), ','));
  EXPECT_EQ(trunk.rfind("trunk,0,-1,100.000000", 0), 0u) << trunk;
  EXPECT_NE(branch.find(",90.00,"), std::string::npos) << branch;
  EXPECT_EQ(std::count(header.begin(), header.end(), ','),
            std::count(branch.begin(), branch.end(), ','));
  EXPECT_NE(branch.find(",0.400,0,0,0.00400,0.02150"), std::string::npos) << branch;
}

TEST(CylinderCsv, TurnedDownCandidatesGiveWhereAndWhy) {
  modeling::RejectedBranch near_trunk;
  near_trunk.centroid = Eigen::Vector3d(-0.25, 0.5, 1.125);
  near_trunk.points = 644;
  near_trunk.reason = modeling::BranchRejection::NOT_AT_THE_SURFACE;
  modeling::RejectedBranch left;
  left.points = 90;
  left.reason = modeling::BranchRejection::REMAINDER_NOT_SEARCHED;
  left.budget_spent = true;
  EXPECT_EQ(io::turnedDownToCsv({near_trunk, left}, Eigen::Vector3d(100, 0, 0)),
            "centroid_x,centroid_y,centroid_z,points,reason,budget_spent\n"
            "99.750000,0.500000,1.125000,644,not at the surface,0\n"
            "100.000000,0.000000,0.000000,90,remainder not searched,1\n");
  EXPECT_EQ(io::turnedDownToCsv({}),
            "centroid_x,centroid_y,centroid_z,points,reason,budget_spent\n");
}

TEST(RenderModelTool, FarPointsAreSkippedAndAModelThatIsNoTreeIsRefused) {
  test::TempDir dir;
  // A 2 m trunk, and a cloud with points near +-1e30 beside the tree's.
  std::string cloud = "0 0 0.5\n0.05 0 1\n";
  for (int i = 0; i < 50; ++i)
    cloud += (i % 2 ? "1e30 " : "-1e30 ") + std::to_string(i) + " 1e30\n";
  const auto cloud_path = dir.write("far.xyz", cloud);
  modeling::TreeModel m;
  modeling::CylinderModel t;
  t.center = Eigen::Vector3d(0, 0, 1);
  t.length = 2.0;
  t.diameter = 0.1;
  m.trunk.push_back(t);
  const auto model_path = dir.write("model.json", io::modelToJson(m));
  std::string out;
  ASSERT_EQ(run("render_model", cloud_path + " " + model_path + " -o " + dir.file("a.png"), &out),
            0)
      << out;
  EXPECT_LT(std::filesystem::file_size(dir.file("a.png")), 1000000u);
  m.trunk[0].center = Eigen::Vector3d(1e30, 0, 1e30);
  const auto far_model = dir.write("far.json", io::modelToJson(m));
  EXPECT_EQ(run("render_model", cloud_path + " " + far_model + " -o " + dir.file("b.png"), &out),
            3);
  EXPECT_NE(out.find("not a tree"), std::string::npos) << out;
}

TEST(ConfigReferenceTool, ShippedParameterFilesAndTheirDocAreTheCodesTables) {
  std::string out;
  EXPECT_EQ(run("config_reference", std::string("--check ") + DTM_CONFIG_DIR + "/..", &out), 0)
      << out;
  test::TempDir dir;
  std::filesystem::create_directories(dir.file("config"));
  std::filesystem::create_directories(dir.file("docs"));
  ASSERT_EQ(run("config_reference", "--write " + dir.file(""), &out), 0) << out;
  std::ofstream(dir.file("config/view_plan.yaml"), std::ios::app) << "# edited by hand\n";
  EXPECT_EQ(run("config_reference", "--check " + dir.file(""), &out), 1) << out;
  EXPECT_NE(out.find("config/view_plan.yaml differs"), std::string::npos) << out;
  EXPECT_EQ(out.find("tree_modeler.yaml"), std::string::npos) << out;
}

TEST(Lms111DecodeTool, DecodesTheRealTelegramAndRejectsOthers) {
  test::TempDir dir;
  std::string out;
  const std::string real = std::string(DTM_SHARED_DATA_DIR) + "/lms1xx/lms1xx_scan_541pts.txt";
  ASSERT_EQ(run("lms111_decode", real, &out), 0) << out;
  EXPECT_NE(out.find("\"name\": \"DIST1\""), std::string::npos);
  EXPECT_NE(out.find("\"count\": 541"), std::string::npos);
  EXPECT_NE(out.find("\"start_angle_deg\": -45.0"), std::string::npos);
  EXPECT_NE(out.find("\"serial_number\": \"A037B9\""), std::string::npos);
  // With STX/ETX and garbage around it, the same telegram.
  {
    std::ifstream in(real);
    std::string text((std::istreambuf_iterator<char>(in)), {});
    std::ofstream(dir.file("framed.bin"))
        << "xx\x02" << text.substr(0, text.find_last_not_of("\r\n") + 1) << "\x03yy";
  }
  std::string framed;
  EXPECT_EQ(run("lms111_decode", dir.file("framed.bin"), &framed), 0) << framed;
  EXPECT_EQ(framed, out);
  EXPECT_EQ(run("lms111_decode", "", &out), 2);
  EXPECT_EQ(run("lms111_decode", dir.file("absent.txt"), &out), 3);
  std::ofstream(dir.file("other.txt")) << "sRA STlms 7";
  EXPECT_EQ(run("lms111_decode", dir.file("other.txt"), &out), 4);
  EXPECT_NE(out.find("not a scan telegram"), std::string::npos) << out;
  EXPECT_EQ(run("lms111_decode", dir.file(""), &out), 3);  // a directory
  EXPECT_NE(out.find("is a directory"), std::string::npos) << out;
}

TEST(EmulatorTools, RefuseAPortTcpCannotHaveAndATelegramThatIsADirectory) {
  test::TempDir dir;
  std::string out;
  // 70000 once wrapped to 4464 silently; a directory as the telegram aborted the emulator.
  EXPECT_EQ(run("lms111_emulator", "--cola-a-port 70000", &out), 3) << out;
  EXPECT_NE(out.find("not 70000"), std::string::npos) << out;
  EXPECT_EQ(run("aerotech_emulator", "--port 70000", &out), 3) << out;
  EXPECT_NE(out.find("not 70000"), std::string::npos) << out;
  EXPECT_EQ(
      run("lms111_emulator", "--cola-a-port 0 --cola-b-port -1 --telegram " + dir.file(""), &out),
      3)
      << out;
  EXPECT_NE(out.find("is a directory"), std::string::npos) << out;
}

// Counts the lines that contain `part`.
std::size_t linesWith(const std::string& text, const std::string& part) {
  std::istringstream in(text);
  std::size_t n = 0;
  for (std::string line; std::getline(in, line);)
    n += line.find(part) != std::string::npos;
  return n;
}

TEST(Lms111DecodeTool, SummarisesARealCoLaBSessionAndReportsBrokenFramesByOffset) {
  test::TempDir dir;
  std::string out;
  const std::string session = std::string(DTM_SHARED_DATA_DIR) + "/lms1xx/lms511_session_colab.txt";
  ASSERT_EQ(run("lms111_decode", "--summary " + session, &out), 0) << out;
  EXPECT_EQ(linesWith(out, "sSN LMDscandata telegram"), 20u) << out;
  EXPECT_EQ(linesWith(out, "25.00 Hz 1141 beams -5.0000..185.0380 deg"), 20u);
  EXPECT_NE(out.find("@0 t=0.202789 sMN SetAccessMode"), std::string::npos) << out;
  EXPECT_NE(out.find("session (CoLa-B): 123 telegrams decoded, 0 failed"), std::string::npos);
  // The same bytes as a binary capture, with one checksum broken and the end cut off.
  std::string bytes;
  for (const auto& t : lms111::readSessionFile(session))
    bytes += lms111::frameColaB(t.payload);
  const std::size_t broken = bytes.find(lms111::frameColaB("sAN Run \x01"));
  ASSERT_NE(broken, std::string::npos);
  bytes[broken + 8 + 9] ^= 0x10;  // the payload's last byte: the checksum no longer matches
  std::ofstream(dir.file("capture.bin"), std::ios::binary) << bytes.substr(0, bytes.size() - 100);
  ASSERT_EQ(run("lms111_decode", "--summary " + dir.file("capture.bin"), &out), 4) << out;
  EXPECT_NE(out.find("@" + std::to_string(broken) + ": bad checksum"), std::string::npos) << out;
  EXPECT_NE(out.find("cut-off frame"), std::string::npos) << out;
  EXPECT_EQ(linesWith(out, "sSN LMDscandata telegram"), 20u) << "decoding went on";
  // Without --summary: each scan as JSON.
  ASSERT_EQ(run("lms111_decode", session, &out), 0);
  EXPECT_EQ(linesWith(out, "\"count\": 1141"), 40u);  // DIST1 and RSSI1 of 20 scans
}

}  // namespace
}  // namespace dormant_tree_modeling
