#include <gtest/gtest.h>
#include <unistd.h>

#include <cmath>
#include <functional>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/io/pose_json.h"
#include "dormant_tree_modeling/io/tree_json.h"
#include "temp_dir.h"

namespace dormant_tree_modeling {
namespace {

modeling::TreeModel sampleModel() {
  modeling::TreeModel m;
  m.input_points = 123456;
  m.runtime_s = 1.5;
  modeling::CylinderModel t0;
  t0.id = 0;
  t0.center = {0.1, -0.2, 0.3};
  t0.axis = {0.0, 0.0, 1.0};
  t0.diameter = 0.062;
  t0.length = 0.45;
  t0.num_points = 2100;
  t0.inlier_ratio = 0.875;
  m.trunk.push_back(t0);
  modeling::PrimaryBranch b;
  b.cylinder.id = 7;
  b.cylinder.center = {0.4, -0.2, 0.5};
  b.cylinder.axis = {1.0, 0.0, 0.0};
  b.cylinder.diameter = 0.021;
  b.cylinder.length = 0.3;
  b.cylinder.num_points = 300;
  b.trunk_segment = 0;
  b.measurement.attachment_height = 0.55;
  b.measurement.angle_to_trunk = M_PI / 2;
  b.measurement.trunk_diameter = 0.06;
  b.measurement.diameter_ratio = 0.35;
  b.measurement.prune = false;
  b.measurement.diameter_resolved = false;
  b.measurement.diameter_min = 0.004;
  b.measurement.diameter_max = 0.0215;
  m.primary_branches.push_back(b);
  return m;
}

ErrorCode errorOf(const std::function<void()>& fn, std::string* message = nullptr) {
  try {
    fn();
  } catch (const Error& e) {
    if (message)
      *message = e.what();
    return e.code();
  }
  ADD_FAILURE() << "no Error thrown";
  return ErrorCode::INVALID_ARGUMENT;
}

TEST(ModelJson, RoundTrip) {
  const auto m = sampleModel();
  const auto back = io::modelFromJson(io::modelToJson(m));
  EXPECT_EQ(back.input_points, 123456u);
  EXPECT_DOUBLE_EQ(back.runtime_s, 1.5);
  ASSERT_EQ(back.trunk.size(), 1u);
  EXPECT_EQ(back.trunk[0].id, 0);
  EXPECT_TRUE(back.trunk[0].center.isApprox(m.trunk[0].center));
  EXPECT_DOUBLE_EQ(back.trunk[0].diameter, 0.062);
  EXPECT_DOUBLE_EQ(back.trunk[0].length, 0.45);
  EXPECT_EQ(back.trunk[0].num_points, 2100u);
  EXPECT_DOUBLE_EQ(back.trunk[0].inlier_ratio, 0.875);
  ASSERT_EQ(back.primary_branches.size(), 1u);
  const auto& b = back.primary_branches[0];
  EXPECT_EQ(b.cylinder.id, 7);
  EXPECT_EQ(b.trunk_segment, 0);
  EXPECT_DOUBLE_EQ(b.cylinder.diameter, 0.021);
  EXPECT_NEAR(b.measurement.angle_to_trunk, M_PI / 2, 1e-12);
  EXPECT_DOUBLE_EQ(b.measurement.diameter_ratio, 0.35);
  EXPECT_FALSE(b.measurement.prune);
  EXPECT_FALSE(b.measurement.diameter_resolved);
  EXPECT_DOUBLE_EQ(b.measurement.diameter_min, 0.004);
  EXPECT_DOUBLE_EQ(b.measurement.diameter_max, 0.0215);
}

TEST(ModelJson, WritesTheDocumentedKeysAndOffset) {
  const std::string text = io::modelToJson(sampleModel(), Eigen::Vector3d(1000.0, 0.0, 0.0));
  for (const char* key :
       {"\"format\": \"dormant_tree_model/1\"", "\"units\": \"m\"", "\"input_points\"", "\"trunk\"",
        "\"primary_branches\"", "\"trunk_segment\"", "\"center\"", "\"axis\"", "\"diameter\"",
        "\"length\"", "\"num_points\""}) {
    EXPECT_NE(text.find(key), std::string::npos) << key;
  }
  const auto back = io::modelFromJson(text);
  EXPECT_NEAR(back.trunk[0].center.x(), 1000.1, 1e-9);
}

TEST(ModelJson, ParsesAMinimalForeignDocumentAndNormalisesAxes) {
  const auto m = io::modelFromJson(R"({"format": "dormant_tree_model/1", "units": "m",
    "trunk": [{"id": 3, "center": [0,0,1], "axis": [0,0,2], "diameter": 0.05, "length": 1}],
    "primary_branches": [{"id": 4, "center": [0.2,0,1], "axis": [1,0,0], "diameter": 0.01,
      "length": 0.3}], "extra": {"anything": true}})");
  ASSERT_EQ(m.trunk.size(), 1u);
  ASSERT_EQ(m.primary_branches.size(), 1u);
  EXPECT_TRUE(m.primary_branches[0].measurement.diameter_resolved);
  // Without a range the diameter is all the document says.
  EXPECT_DOUBLE_EQ(m.primary_branches[0].measurement.diameter_min, 0.01);
  EXPECT_DOUBLE_EQ(m.primary_branches[0].measurement.diameter_max, 0.01);
  EXPECT_DOUBLE_EQ(m.trunk[0].axis.z(), 1.0);
  EXPECT_EQ(m.trunk[0].num_points, 0u);
}

TEST(ModelJson, BadDocumentsNameTheProblem) {
  std::string msg;
  EXPECT_EQ(errorOf([] { io::modelFromJson("{not json"); }), ErrorCode::PARSE_ERROR);
  EXPECT_EQ(errorOf([] { io::modelFromJson("[]"); }), ErrorCode::PARSE_ERROR);
  EXPECT_EQ(errorOf([&] { io::modelFromJson(R"({"format": "dormant_tree_truth/1"})"); }, &msg),
            ErrorCode::PARSE_ERROR);
  EXPECT_NE(msg.find("expected 'dormant_tree_model/1'"), std::string::npos) << msg;
  EXPECT_EQ(errorOf(
                [] {
                  io::modelFromJson(R"({"format": "dormant_tree_model/1", "trunk": [{"id": 0,
                    "center": [0,0], "axis": [0,0,1], "diameter": 1, "length": 1}],
                    "primary_branches": []})");
                },
                &msg),
            ErrorCode::PARSE_ERROR);
  EXPECT_NE(msg.find("trunk[0].center"), std::string::npos) << msg;
  EXPECT_EQ(errorOf(
                [] {
                  io::modelFromJson(R"({"format": "dormant_tree_model/1", "trunk": [],
                    "primary_branches": [{"id": 0, "center": [0,0,0], "axis": [0,0,0],
                    "diameter": 1, "length": 1}]})");
                },
                &msg),
            ErrorCode::PARSE_ERROR);
  EXPECT_NE(msg.find("axis is zero"), std::string::npos) << msg;
  EXPECT_EQ(errorOf([] {
              io::modelFromJson(R"({"format": "dormant_tree_model/1", "units": "cm",
                "trunk": [], "primary_branches": []})");
            }),
            ErrorCode::PARSE_ERROR);
}

evaluation::GroundTruth sampleTruth() {
  evaluation::GroundTruth t;
  t.trunk.points = {{0, 0, 0}, {0, 0, 1}, {0.01, 0, 2}};
  t.trunk.diameters = {0.06, 0.04, 0.02};
  evaluation::Polyline b;
  b.id = 0;
  b.points = {{0, 0, 0.8}, {0.5, 0, 0.85}};
  b.diameters = {0.02, 0.01};
  t.primary_branches.push_back(b);
  evaluation::Polyline minor;
  minor.id = 100;
  minor.points = {{0, 0, 1.2}, {0, 0.1, 1.25}};
  minor.diameters = {0.005, 0.003};
  t.minor_branches.push_back(minor);
  return t;
}

TEST(ModelJson, ANumberNoDoubleHoldsOrAValueOfTheWrongTypeIsAParseError) {
  // Found by make fuzz: nlohmann's out_of_range for 1e499 escaped as another exception type.
  for (const char* text :
       {"\n1e499\n",
        R"({"format": "dormant_tree_model/1", "units": "m", "trunk": [{"id": "abc"}]})"}) {
    for (const auto& read : {std::function<void()>([&] { io::modelFromJson(text); }),
                             std::function<void()>([&] { io::truthFromJson(text); })}) {
      try {
        read();
        ADD_FAILURE() << text;
      } catch (const Error& e) {
        EXPECT_EQ(e.code(), ErrorCode::PARSE_ERROR) << e.what();
      }
    }
  }
}

TEST(PoseJson, RejectsAZeroOrScaledQuaternionAndNonFiniteNumbers) {
  const auto pose = [](const std::string& text) {
    return io::poseFromJson(nlohmann::json::parse(text), "guess_pose");
  };
  const std::string t = R"("translation": [1, 2, 3], )";
  EXPECT_TRUE(
      pose("{\"guess_pose\": {" + t + R"("rotation_xyzw": [0, 0, 0.7071068, 0.7071068]}})"));
  EXPECT_FALSE(pose("{}"));
  for (const char* bad : {"[0, 0, 0, 0]", "[0, 0, 0, 2]", "[0, 0, 0, 0.9]"}) {
    try {
      pose("{\"guess_pose\": {" + t + "\"rotation_xyzw\": " + bad + "}}");
      ADD_FAILURE() << bad;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::PARSE_ERROR);
      EXPECT_NE(std::string(e.what()).find("unit quaternion"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(
      pose(R"({"guess_pose": {"translation": [1e999, 0, 0], "rotation_xyzw": [0, 0, 0, 1]}})"),
      std::exception);
}

TEST(TruthJson, RoundTripThroughAFile) {
  test::TempDir dir;
  const auto path = dir.file("truth.json");
  io::writeTextFile(path, io::truthToJson(sampleTruth()));
  const auto t = io::readTruthFile(path);
  ASSERT_EQ(t.trunk.points.size(), 3u);
  EXPECT_DOUBLE_EQ(t.trunk.points[2].x(), 0.01);
  EXPECT_DOUBLE_EQ(t.trunk.diameters[1], 0.04);
  ASSERT_EQ(t.primary_branches.size(), 1u);
  EXPECT_EQ(t.primary_branches[0].id, 0);
  ASSERT_EQ(t.minor_branches.size(), 1u);
  EXPECT_EQ(t.minor_branches[0].id, 100);
  EXPECT_DOUBLE_EQ(t.minor_branches[0].diameters[1], 0.003);
}

TEST(TruthJson, MinorBranchesAreOptionalAndExtraKeysIgnored) {
  const auto t = io::truthFromJson(R"({"format": "dormant_tree_truth/1", "units": "m",
    "seed": 42, "trunk": {"points": [[0,0,0],[0,0,1]], "diameters": [0.05, 0.03]},
    "primary_branches": []})");
  EXPECT_TRUE(t.minor_branches.empty());
  EXPECT_EQ(t.trunk.points.size(), 2u);
}

TEST(TruthJson, InconsistentPolylinesAreRejected) {
  std::string msg;
  EXPECT_EQ(errorOf(
                [] {
                  io::truthFromJson(R"({"format": "dormant_tree_truth/1",
                    "trunk": {"points": [[0,0,0],[0,0,1]], "diameters": [0.05]}})");
                },
                &msg),
            ErrorCode::PARSE_ERROR);
  EXPECT_NE(msg.find("2 points but 1 diameters"), std::string::npos) << msg;
  EXPECT_EQ(errorOf(
                [] {
                  io::truthFromJson(R"({"format": "dormant_tree_truth/1",
                    "trunk": {"points": [[0,0,0],[0,0,1]], "diameters": [0.05, -1]}})");
                },
                &msg),
            ErrorCode::PARSE_ERROR);
  EXPECT_NE(msg.find("diameters[1] must be positive"), std::string::npos) << msg;
  EXPECT_EQ(errorOf([] {
              io::truthFromJson(R"({"format": "dormant_tree_truth/1",
                    "trunk": {"points": [[0,0,0]], "diameters": [0.05]}})");
            }),
            ErrorCode::PARSE_ERROR);
  EXPECT_EQ(errorOf([] {
              io::truthFromJson(R"({"format": "dormant_tree_truth/1",
                "trunk": {"points": [[0,0,0],[0,0,1]], "diameters": [0.05,0.04]},
                "primary_branches": [{"points": [[0,0,0],[1,0,0]], "diameters": [0.01,0.01]}]})");
            }),
            ErrorCode::PARSE_ERROR);  // a branch without id
}

TEST(TruthJson, MissingFileNamesThePath) {
  std::string msg;
  EXPECT_EQ(errorOf([] { io::readTruthFile("/nonexistent/truth.json"); }, &msg),
            ErrorCode::FILE_NOT_FOUND);
  EXPECT_NE(msg.find("/nonexistent/truth.json"), std::string::npos);
}

TEST(TruthJson, ParseErrorInFileNamesThePath) {
  test::TempDir dir;
  const auto path = dir.write("truth.json", "{\"format\": \"dormant_tree_truth/1\"}");
  std::string msg;
  EXPECT_EQ(errorOf([&] { io::readTruthFile(path); }, &msg), ErrorCode::PARSE_ERROR);
  EXPECT_NE(msg.find(path), std::string::npos) << msg;
  EXPECT_NE(msg.find("'trunk'"), std::string::npos) << msg;
}

TEST(TransformModel, MovesCentresRotatesAxesKeepsSizes) {
  modeling::TreeModel m;
  modeling::CylinderModel trunk;
  trunk.center = {1.0, 0.0, 0.5};
  trunk.axis = {0.0, 0.0, 1.0};
  trunk.diameter = 0.08;
  m.trunk.push_back(trunk);
  modeling::PrimaryBranch b;
  b.cylinder.center = {1.2, 0.0, 0.8};
  b.cylinder.axis = {1.0, 0.0, 0.0};
  b.cylinder.diameter = 0.02;
  b.measurement.attachment_height = 0.7;
  m.primary_branches.push_back(b);
  // A quarter turn about z, then 10 m along x.
  Eigen::Isometry3d pose =
      Eigen::Translation3d(10.0, 0.0, 0.0) * Eigen::AngleAxisd(M_PI / 2, Eigen::Vector3d::UnitZ());
  const modeling::TreeModel t = modeling::transformModel(m, pose);
  EXPECT_TRUE(t.trunk[0].center.isApprox(Eigen::Vector3d(10.0, 1.0, 0.5), 1e-12));
  EXPECT_TRUE(t.trunk[0].axis.isApprox(Eigen::Vector3d(0.0, 0.0, 1.0), 1e-12));
  EXPECT_TRUE(
      t.primary_branches[0].cylinder.center.isApprox(Eigen::Vector3d(10.0, 1.2, 0.8), 1e-12));
  EXPECT_NEAR(t.primary_branches[0].cylinder.axis.y(), 1.0, 1e-12);
  EXPECT_DOUBLE_EQ(t.primary_branches[0].cylinder.diameter, 0.02);
  EXPECT_DOUBLE_EQ(t.primary_branches[0].measurement.attachment_height, 0.7);
  EXPECT_DOUBLE_EQ(t.trunk[0].diameter, 0.08);
}

}  // namespace
}  // namespace dormant_tree_modeling
