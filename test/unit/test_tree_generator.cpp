#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/io/tree_json.h"
#include "dormant_tree_modeling/simulation/dataset.h"
#include "dormant_tree_modeling/simulation/orchard_generator.h"
#include "dormant_tree_modeling/simulation/ray_caster.h"
#include "temp_dir.h"

namespace dormant_tree_modeling {
namespace simulation {
namespace {

double length(const std::vector<Eigen::Vector3d>& p) {
  double l = 0;
  for (std::size_t i = 1; i < p.size(); ++i)
    l += (p[i] - p[i - 1]).norm();
  return l;
}

TEST(Presets, UnknownNameListsTheKnownOnes) {
  try {
    presetParams("bonsai");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::INVALID_ARGUMENT);
    EXPECT_NE(std::string(e.what()).find("young_tall_spindle"), std::string::npos);
  }
}

TEST(TreeGenerator, YoungTallSpindleStaysInItsRanges) {
  const TreeConfig p = presetParams("young_tall_spindle");
  int large_ratio = 0;
  for (std::uint64_t seed = 1; seed <= 10; ++seed) {
    const TreeObject tree = generateTree(p, seed, Eigen::Vector3d::Zero());
    const auto truth = truthFromTree(tree);
    const auto& trunk = truth.trunk;
    EXPECT_GE(length(trunk.points), 2.5 - 1e-9);
    EXPECT_LE(length(trunk.points), 4.0 * 1.02);  // sway adds a little arc length
    EXPECT_GE(trunk.diameters.front(), 0.04);
    EXPECT_LE(trunk.diameters.front(), 0.08);
    EXPECT_NEAR(trunk.diameters.back(), 0.015, 1e-9);
    const double lean = std::acos((trunk.points.back() - trunk.points.front()).normalized().z());
    EXPECT_LE(lean, 12.0 * M_PI / 180.0);
    EXPECT_GE(truth.primary_branches.size(), 15u);
    EXPECT_LE(truth.primary_branches.size(), 40u);
    for (const auto& b : truth.primary_branches) {
      EXPECT_GE(b.diameters.front(), PRIMARY_MIN_BASE_DIAMETER - 1e-12);
      EXPECT_LE(b.diameters.front(), 0.035 + 1e-12);
      EXPECT_GE(length(b.points), PRIMARY_MIN_LENGTH);
      // Starts on the trunk axis.
      double nearest = 1e9;
      for (const auto& q : trunk.points)
        nearest = std::min(nearest, (q - b.points.front()).norm());
      EXPECT_LT(nearest, 1e-9);
      // Ratio to the local trunk diameter.
      std::size_t k = 0;
      for (std::size_t i = 0; i < trunk.points.size(); ++i) {
        if ((trunk.points[i] - b.points.front()).norm() < 1e-9)
          k = i;
      }
      if (b.diameters.front() / trunk.diameters[k] > 0.5)
        ++large_ratio;
    }
    for (const auto& m : truth.minor_branches) {
      EXPECT_TRUE(m.diameters.front() < PRIMARY_MIN_BASE_DIAMETER ||
                  length(m.points) < PRIMARY_MIN_LENGTH);
    }
    EXPECT_FALSE(truth.minor_branches.empty());
  }
  EXPECT_GT(large_ratio, 10);  // pruning candidates exist
}

TEST(TreeGenerator, CentralLeaderHasFewThickScaffolds) {
  const TreeConfig p = presetParams("central_leader");
  for (std::uint64_t seed = 1; seed <= 5; ++seed) {
    const auto truth = truthFromTree(generateTree(p, seed, Eigen::Vector3d::Zero()));
    EXPECT_GE(truth.trunk.diameters.front(), 0.10);
    EXPECT_LE(truth.trunk.diameters.front(), 0.20);
    EXPECT_GE(truth.primary_branches.size(), 6u);
    EXPECT_LE(truth.primary_branches.size(), 15u);
    for (const auto& b : truth.primary_branches)
      EXPECT_LE(b.diameters.front(), 0.08 + 1e-12);
  }
}

TEST(TreeGenerator, TruthLiesInsideTheGeometry) {
  for (const char* preset : {"young_tall_spindle", "mature_tall_spindle", "central_leader"}) {
    const Orchard orchard = generateOrchard(OrchardConfig{preset}, 11);
    const RayCaster caster(orchard.scene);
    std::vector<evaluation::Polyline> lines = orchard.truth.primary_branches;
    lines.push_back(orchard.truth.trunk);
    int checked = 0;
    for (const auto& line : lines) {
      for (std::size_t i = 1; i + 1 < line.points.size(); ++i) {
        const Eigen::Vector3d t = (line.points[i + 1] - line.points[i - 1]).normalized();
        const Eigen::Vector3d n1 = t.unitOrthogonal(), n2 = t.cross(n1);
        for (const Eigen::Vector3d& d : {n1, n2, Eigen::Vector3d(-n1), Eigen::Vector3d(-n2)}) {
          // From a point of the true centreline, the wall of the object is within the true radius.
          const auto hit = caster.cast(Ray{line.points[i], d}, 0.0, 10.0);
          ASSERT_TRUE(hit) << preset;
          EXPECT_LE(hit->t, 0.5 * line.diameters[i] + 1e-9) << preset << " vertex " << i;
          ++checked;
        }
      }
    }
    EXPECT_GT(checked, 400);
  }
}

TEST(OrchardGenerator, ClutterAroundTheTarget) {
  const Orchard o = generateOrchard(OrchardConfig{}, 3);
  EXPECT_EQ(o.scene.trees.size(), 1u + 2u + 6u);
  EXPECT_EQ(o.scene.wires.size(), 5u);
  EXPECT_EQ(o.scene.posts.size(), 1u);
  for (const auto& w : o.scene.wires) {
    EXPECT_GE(2 * w.radius, 0.002);
    EXPECT_LE(2 * w.radius, 0.004);
  }
  const double left = -o.scene.trees[1].branches[0].points[0].x();
  const double right = o.scene.trees[2].branches[0].points[0].x();
  EXPECT_GE(left, 0.9);
  EXPECT_LE(left, 1.2);
  EXPECT_GE(right, 0.9);
  EXPECT_LE(right, 1.2);
  EXPECT_THROW(generateOrchard(OrchardConfig{"unknown"}, 3), Error);
}

TEST(Scene, SaveLoadRoundTrip) {
  test::TempDir dir;
  const Orchard o = generateOrchard(OrchardConfig{}, 5);
  saveScene(o.scene, dir.file("scene.json"));
  const Scene back = loadScene(dir.file("scene.json"));
  ASSERT_EQ(back.trees.size(), o.scene.trees.size());
  EXPECT_EQ(back.trees[0].branches.size(), o.scene.trees[0].branches.size());
  EXPECT_TRUE(back.trees[0].branches[3].points[2].isApprox(o.scene.trees[0].branches[3].points[2]));
  EXPECT_DOUBLE_EQ(back.wires[1].radius, o.scene.wires[1].radius);
  EXPECT_DOUBLE_EQ(back.posts[0].radius, o.scene.posts[0].radius);
  // A caster from the loaded scene sees the same surface.
  const Ray r{Eigen::Vector3d(0, -2, 1.0), Eigen::Vector3d(0, 1, 0)};
  const auto a = RayCaster(o.scene).cast(r, 0, 10), b = RayCaster(back).cast(r, 0, 10);
  ASSERT_EQ(a.has_value(), b.has_value());
  if (a)
    EXPECT_NEAR(a->t, b->t, 1e-12);
  EXPECT_THROW(loadScene(dir.file("missing.json")), Error);
  dir.write("bad.json", "{\"format\": \"something else\"}");
  EXPECT_THROW(loadScene(dir.file("bad.json")), Error);
}

std::string slurp(const std::string& path) {
  std::ifstream f(path, std::ios::binary);
  std::ostringstream s;
  s << f.rdbuf();
  return s.str();
}

DatasetConfig smallDataset() {
  DatasetConfig o;
  o.seed = 21;
  o.plan.heights_m = {1.5};
  o.plan.positions_per_height = 1;
  o.plan.slide_steps = 2;
  o.plan.back = false;
  o.plan.theta_step_deg = 4.5;  // 20 lines
  return o;
}

TEST(Dataset, SameSeedGivesByteIdenticalFilesOnAnyThreadCount) {
  test::TempDir dir;
  DatasetConfig a = smallDataset();
  a.threads = 1;
  DatasetConfig b = smallDataset();
  b.threads = 2;
  const auto sa = writeDataset(a, dir.file("a"));
  writeDataset(b, dir.file("b"));
  EXPECT_EQ(sa.views, 2);
  EXPECT_GT(sa.merged_points, 1000u);
  for (const char* f :
       {"truth.json", "scene.json", "views.json", "merged.pcd", "merged.ply", "target.pcd",
        "preview.png", "views/view_01.pcd", "views/view_01_range.pgm"}) {
    const std::string fa = slurp(dir.file(std::string("a/") + f));
    EXPECT_FALSE(fa.empty()) << f;
    EXPECT_EQ(fa, slurp(dir.file(std::string("b/") + f))) << f;
  }
  DatasetConfig c = smallDataset();
  c.seed = 22;
  writeDataset(c, dir.file("c"));
  EXPECT_NE(slurp(dir.file("a/merged.pcd")), slurp(dir.file("c/merged.pcd")));
  // The truth file is the documented format.
  const auto truth = io::readTruthFile(dir.file("a/truth.json"));
  EXPECT_EQ(static_cast<int>(truth.primary_branches.size()), sa.primary_branches);
}

TEST(Dataset, GuessPosesArePerturbedWithinTheConfiguredBounds) {
  test::TempDir dir;
  DatasetConfig o = smallDataset();
  o.write_views = false;
  writeDataset(o, dir.file("d"));
  const auto doc = nlohmann::json::parse(slurp(dir.file("d/views.json")));
  ASSERT_EQ(doc.at("views").size(), 2u);
  for (const auto& v : doc.at("views")) {
    const auto t = v.at("true_pose"), g = v.at("guess_pose");
    const Eigen::Vector3d dt(g["translation"][0].get<double>() - t["translation"][0].get<double>(),
                             g["translation"][1].get<double>() - t["translation"][1].get<double>(),
                             g["translation"][2].get<double>() - t["translation"][2].get<double>());
    const Eigen::Quaterniond qt(
        t["rotation_xyzw"][3].get<double>(), t["rotation_xyzw"][0].get<double>(),
        t["rotation_xyzw"][1].get<double>(), t["rotation_xyzw"][2].get<double>());
    const Eigen::Quaterniond qg(
        g["rotation_xyzw"][3].get<double>(), g["rotation_xyzw"][0].get<double>(),
        g["rotation_xyzw"][1].get<double>(), g["rotation_xyzw"][2].get<double>());
    // The slide offset (up to 0.05 m here) turns with the heading error.
    EXPECT_LE(dt.head<2>().norm(), o.guess_max_translation + 0.05 * 0.35);
    EXPECT_LE(std::abs(dt.z()), 0.05);
    EXPECT_LE(qt.angularDistance(qg), o.guess_max_yaw_deg * M_PI / 180.0 + 1e-9);
    EXPECT_GT(dt.norm() + qt.angularDistance(qg), 1e-3);  // really perturbed
  }
  EXPECT_FALSE(std::filesystem::exists(dir.file("d/views/view_00.pcd")));
}

}  // namespace
}  // namespace simulation
}  // namespace dormant_tree_modeling
