#include <gtest/gtest.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <limits>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/random.h"
#include "dormant_tree_modeling/evaluation/matching.h"
#include "dormant_tree_modeling/io/point_cloud_io.h"
#include "dormant_tree_modeling/io/tree_json.h"
#include "dormant_tree_modeling/modeling/tree_modeler.h"
#include "dormant_tree_modeling/simulation/dataset.h"
#include "sensor_model.h"
#include "temp_dir.h"

namespace dormant_tree_modeling {
namespace modeling {
namespace {

ErrorCode errorOf(const TreeModeler& modeler, const Points& pts) {
  try {
    modeler.model(pts);
  } catch (const Error& e) {
    return e.code();
  }
  return ErrorCode::IO_FAILURE;  // not thrown: fails the comparisons below
}

TEST(TreeModeler, BadInputsGiveDocumentedErrors) {
  const TreeModeler modeler(ModelerConfig{});
  EXPECT_EQ(errorOf(modeler, {}), ErrorCode::EMPTY_INPUT);
  const double nan = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(errorOf(modeler, Points(500, Eigen::Vector3d(nan, 0, 0))), ErrorCode::EMPTY_INPUT);
  EXPECT_EQ(errorOf(modeler, Points(50, Eigen::Vector3d::Ones())), ErrorCode::EMPTY_INPUT);
  // A flat patch of ground has no trunk.
  Points ground;
  for (int i = 0; i < 60; ++i) {
    for (int k = 0; k < 60; ++k)
      ground.emplace_back(0.01 * i, 0.01 * k, 0.0);
  }
  ModelerConfig keep_ground;
  keep_ground.preprocess.remove_clutter = false;
  EXPECT_EQ(errorOf(TreeModeler(keep_ground), ground), ErrorCode::NO_TRUNK);
  ModelerConfig bad;
  bad.graph.psi_t_deg = 0.0;
  EXPECT_THROW(TreeModeler{bad}, Error);
}

TEST(TreeModeler, NoiseFillingAVolumeIsNoTreeAndIsToldEarly) {
  Rng rng(21);
  Points noise;  // what the modeler once turned into a 20 cm trunk in 66 s at 1e6 points
  for (int i = 0; i < 100000; ++i)
    noise.emplace_back(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(0.0, 3.0));
  try {
    TreeModeler(ModelerConfig{}).model(noise);
    FAIL() << "a model of noise";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::NO_TRUNK);
    EXPECT_NE(std::string(e.what()).find("no tree found"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("volume"), std::string::npos) << e.what();
  }
}

/// A synthetic tree scanned by a reduced plan (8 of the 40 views, full resolution): seconds.
struct Scan {
  CloudPtr cloud;
  evaluation::GroundTruth truth;
};

Scan scanTree(const std::string& preset, std::uint64_t seed, double noise) {
  test::TempDir dir;
  simulation::DatasetConfig o;
  o.orchard.preset = preset;
  o.seed = seed;
  o.sensor.range_noise_sigma = noise;
  o.plan.heights_m = {1.5, 3.0};
  o.plan.positions_per_height = 1;
  o.plan.slide_steps = 2;
  o.plan.slide_step_m = 0.2;
  o.write_views = false;
  simulation::writeDataset(o, dir.file("d"));
  Scan s;
  s.cloud = io::readCloud(dir.file("d/target.pcd")).cloud;
  s.truth = io::readTruthFile(dir.file("d/truth.json"));
  return s;
}

/// How many branch diameters a model says it did not measure, and how many of them are at
/// the floor: each branch at the floor says so, and the model's warnings count them once
/// (none when there are none).
struct Unmeasured {
  std::size_t total = 0, at_floor = 0;
};

Unmeasured unmeasuredBranches(const TreeModel& model) {
  Unmeasured n;
  for (const auto& b : model.primary_branches) {
    const bool floor = b.cylinder.diameter <= 2 * MIN_BRANCH_RADIUS_M + 1e-9;
    if (floor) {
      EXPECT_FALSE(b.measurement.diameter_resolved) << "branch " << b.cylinder.id;
    }
    // A measured diameter is its own range; one not measured spans the floor up to the widest
    // diameter the tables cannot tell from it, which holds the one reported.
    const auto& m = b.measurement;
    EXPECT_LE(m.diameter_min, b.cylinder.diameter + 1e-12) << "branch " << b.cylinder.id;
    EXPECT_GE(m.diameter_max, b.cylinder.diameter - 1e-12) << "branch " << b.cylinder.id;
    if (m.diameter_resolved) {
      EXPECT_NEAR(m.diameter_max - m.diameter_min, 0.0, 1e-12) << "branch " << b.cylinder.id;
    } else {
      EXPECT_DOUBLE_EQ(m.diameter_min, 2 * MIN_BRANCH_RADIUS_M) << "branch " << b.cylinder.id;
    }
    n.total += !b.measurement.diameter_resolved;
    n.at_floor += floor;
  }
  const std::string expected = std::to_string(n.total) + " of " +
                               std::to_string(model.primary_branches.size()) +
                               " branch diameters were not measured";
  const std::string floor_part = std::to_string(n.at_floor) + " corrected to the 4 mm floor";
  std::size_t counted = 0, found = 0;
  for (const auto& w : model.correction.warnings) {
    counted += w.find("were not measured") != std::string::npos;
    found += w.rfind(expected, 0) == 0 && w.find(floor_part) != std::string::npos;
  }
  EXPECT_EQ(counted, n.total > 0 ? 1u : 0u);
  EXPECT_EQ(found, n.total > 0 ? 1u : 0u) << expected;
  return n;
}

TEST(TreeModeler, SyntheticTreeMeetsAccuracyBounds) {
  const Scan scan = scanTree("young_tall_spindle", 3, 0.006);
  const TreeModeler modeler(test::sensorModelConfig());
  const ModelResult result = modeler.model(*scan.cloud);
  const auto score = evaluation::evaluate(result.model, scan.truth);
  RecordProperty("f1", std::to_string(score.f1));
  RecordProperty("branch_mae_mm", std::to_string(1000 * score.branch_mae));
  RecordProperty("trunk_mae_mm", std::to_string(1000 * score.trunk_mae));
  // Bounds a little under what this configuration measures (docs/benchmarks.md):
  // they catch regressions, they are not the product targets, which make bench reports.
  EXPECT_GE(score.f1, 0.75) << evaluation::formatTable({score});
  // Measured with this reduced 4-view plan: F1 0.80, branch MAE 2.8 mm, trunk MAE 2.1 mm.
  EXPECT_LE(score.branch_mae, 0.0045) << evaluation::formatTable({score});
  EXPECT_LE(score.trunk_mae, 0.004) << evaluation::formatTable({score});
  EXPECT_GE(score.coverage, 0.85) << evaluation::formatTable({score});
  EXPECT_EQ(result.classes.size(), result.points.size());
  // The trunk diameter where each branch leaves (the pruning ratio's denominator) against the
  // truth's at that height.
  double base = std::numeric_limits<double>::infinity();
  for (const auto& c : result.model.trunk)
    base = std::min(base, c.center.z() - 0.5 * c.length * std::abs(c.axis.z()));
  const auto& truth_trunk = scan.truth.trunk;
  const auto trueDiameterAt = [&](double z) {
    const auto& p = truth_trunk.points;
    for (std::size_t k = 0; k + 1 < p.size(); ++k) {
      if (z <= p[k + 1].z()) {
        const double f = std::clamp((z - p[k].z()) / (p[k + 1].z() - p[k].z()), 0.0, 1.0);
        return (1.0 - f) * truth_trunk.diameters[k] + f * truth_trunk.diameters[k + 1];
      }
    }
    return truth_trunk.diameters.back();
  };
  double trunk_error = 0.0;
  for (const auto& b : result.model.primary_branches) {
    trunk_error += std::abs(b.measurement.trunk_diameter -
                            trueDiameterAt(base + b.measurement.attachment_height));
  }
  trunk_error /= std::max<std::size_t>(1, result.model.primary_branches.size());
  RecordProperty("trunk_diameter_at_branches_mae_mm", std::to_string(1000 * trunk_error));
  EXPECT_LE(trunk_error, 0.003);
  // Measurements are consistent with the cylinders, and a diameter at the floor says so.
  unmeasuredBranches(result.model);
  for (const auto& b : result.model.primary_branches) {
    EXPECT_NEAR(b.measurement.diameter_ratio, b.cylinder.diameter / b.measurement.trunk_diameter,
                1e-9);
    EXPECT_EQ(b.measurement.prune, b.measurement.diameter_ratio > 0.5);
    EXPECT_GE(b.trunk_segment, 0);
    EXPECT_LT(b.trunk_segment, static_cast<int>(result.model.trunk.size()));
  }
}

TEST(TreeModeler, ABranchCorrectedToTheFloorIsNotAMeasurement) {
  // The correction takes a branch whose RMS radius is all noise to the 4 mm floor: no
  // measurement, and the model says so per branch and once. Told the noise is 20 mm instead of
  // the 7.5 mm it estimates, more of this young tree's 5-15 mm branches end there. Our sensor
  // model's tables read thin branches of several diameters alike (up to 8.6 mm at 6 mm of
  // noise): a reading there is no measurement either, though above the floor.
  const Scan scan = scanTree("young_tall_spindle", 3, 0.006);
  const TreeModeler own_modeler(test::sensorModelConfig());
  const TreeModel own_model = own_modeler.model(*scan.cloud).model;
  const Unmeasured own = unmeasuredBranches(own_model);
  ModelerConfig config = test::sensorModelConfig();
  config.noise.sigma_m = 0.02;
  const Unmeasured told = unmeasuredBranches(TreeModeler(config).model(*scan.cloud).model);
  RecordProperty("at_floor_own_estimate", std::to_string(own.at_floor));
  RecordProperty("unmeasured_own_estimate", std::to_string(own.total));
  RecordProperty("at_floor_told_20mm", std::to_string(told.at_floor));
  EXPECT_GT(told.at_floor, own.at_floor);
  EXPECT_GT(own.total, own.at_floor);
  const double sigma = own_model.correction.table_noise_sigma;
  const auto& table = own_modeler.config().branch_calibration;
  const double reach = table.floorAmbiguity(MIN_BRANCH_RADIUS_M, sigma).radius;
  for (const auto& b : own_model.primary_branches) {
    const double r = 0.5 * b.cylinder.diameter;
    EXPECT_EQ(b.measurement.diameter_resolved, table.resolves(r, sigma, MIN_BRANCH_RADIUS_M))
        << "branch " << b.cylinder.id;
    if (!b.measurement.diameter_resolved) {
      EXPECT_NEAR(b.measurement.diameter_max, 2 * reach, 1e-12) << "branch " << b.cylinder.id;
    }
  }
}

TEST(TreeModeler, ChoosesTheCentredTrunkWhenSomeOfItsTracksStopLow) {
  // Held-out tree (central leader, seed 106, 12 mm noise, full 40-view plan) on which the trunk
  // choice once took the neighbour 0.5 m away: four of the target's seven tracks stopped below
  // 1 m, and their small shells pulled its median score under the neighbour's.
  test::TempDir dir;
  simulation::DatasetConfig o;
  o.orchard.preset = "central_leader";
  o.seed = 106;
  o.sensor.range_noise_sigma = 0.012;
  o.write_views = false;
  simulation::writeDataset(o, dir.file("d"));
  const auto cloud = io::readCloud(dir.file("d/target.pcd")).cloud;
  const auto truth = io::readTruthFile(dir.file("d/truth.json"));
  const ModelResult result = TreeModeler(ModelerConfig{}).model(*cloud);
  ASSERT_FALSE(result.model.trunk.empty());
  const auto& base = result.model.trunk.front();
  const Eigen::Vector3d bottom = base.center - 0.5 * base.length * base.axis;
  EXPECT_LT((bottom.head<2>() - truth.trunk.points.front().head<2>()).norm(), 0.1)
      << "trunk base at " << bottom.transpose();
  const auto score = evaluation::evaluate(result.model, truth);
  // Measured: F1 0.83, trunk MAE 5.7 mm (with the neighbour's trunk: F1 0.22, 32 mm).
  EXPECT_GE(score.f1, 0.75) << evaluation::formatTable({score});
  EXPECT_LE(score.trunk_mae, 0.008) << evaluation::formatTable({score});
}

TEST(TreeModeler, APostBesideTheLeaderIsNoPartOfTheTrunk) {
  // Seed 172's drooping tree at 6 mm: its leader leans to within 4-6 cm of a post (r 59 mm)
  // from 2.3 m up. The trunk's reach took in the post's near side, and with the full plan the
  // upper trunk came out 44-48 mm thick where it is 20-37 mm. The post's points on the other
  // column are left out of the trunk.
  const Scan scan = scanTree("drooping_scaffolds", 172, 0.006);
  const ModelResult result = TreeModeler(test::sensorModelConfig()).model(*scan.cloud);
  EXPECT_GT(result.trunk_column_points, 0);
  const auto score = evaluation::evaluate(result.model, scan.truth);
  RecordProperty("trunk_mae_mm", std::to_string(1000 * score.trunk_mae));
  // Measured with this reduced plan: trunk MAE 1.1 mm (2.4 mm with the post's points in).
  EXPECT_LE(score.trunk_mae, 0.0018) << evaluation::formatTable({score});
}

TEST(TreeModeler, SaysWhatPreprocessingDroppedOrCoarsened) {
  const Scan scan = scanTree("young_tall_spindle", 4, 0.003);
  Points pts;
  for (const auto& p : scan.cloud->points)
    pts.emplace_back(p.x, p.y, p.z);
  EXPECT_TRUE(TreeModeler(ModelerConfig{}).model(pts).notices.empty());
  pts.emplace_back(1e7, 1e7, 1.0);
  ModelerConfig capped;
  capped.preprocess.max_points = 20000;
  const ModelResult result = TreeModeler(capped).model(pts);
  ASSERT_EQ(result.notices.size(), 2u);
  EXPECT_EQ(result.notices[0], "dropped 1 stray points far outside the cloud's bulk");
  EXPECT_NE(result.notices[1].find(std::to_string(result.points.size()) + " points modeled on a "),
            std::string::npos)
      << result.notices[1];
  EXPECT_NE(result.notices[1].find("max_modeled_points (20000)"), std::string::npos)
      << result.notices[1];
}

TEST(TreeModeler, SameInputSameModel) {
  const Scan scan = scanTree("young_tall_spindle", 4, 0.003);
  const TreeModeler modeler(ModelerConfig{});
  const std::string a = io::modelToJson(modeler.model(*scan.cloud).model);
  const std::string b = io::modelToJson(modeler.model(*scan.cloud).model);
  // Runtime differs between runs; everything before it is the model.
  EXPECT_EQ(a.substr(0, a.find("runtime_s")), b.substr(0, b.find("runtime_s")));
}

TEST(TreeModeler, SurveyCoordinatesGiveTheSameModelShifted) {
  const Scan scan = scanTree("young_tall_spindle", 5, 0.003);
  test::TempDir dir;
  const Eigen::Vector3d offset(512345.0, 5412345.0, 210.0);
  io::writeCloud(dir.file("utm.xyz"), *scan.cloud, offset);
  const auto loaded = io::readCloud(dir.file("utm.xyz"));
  EXPECT_FALSE(loaded.offset.isZero());
  const TreeModeler modeler(ModelerConfig{});
  const auto local = modeler.model(*scan.cloud).model;
  const auto shifted =
      io::modelFromJson(io::modelToJson(modeler.model(*loaded.cloud).model, loaded.offset));
  // Recentring moves points by float rounding, which can move a partition; the trunk's base
  // and extent must not move.
  ASSERT_FALSE(local.trunk.empty());
  ASSERT_FALSE(shifted.trunk.empty());
  auto bottom = [](const modeling::TreeModel& m) {
    const auto& c = m.trunk.front();
    return Eigen::Vector3d(c.center - 0.5 * c.length * c.axis);
  };
  auto top = [](const modeling::TreeModel& m) {
    const auto& c = m.trunk.back();
    return Eigen::Vector3d(c.center + 0.5 * c.length * c.axis);
  };
  EXPECT_LT((bottom(shifted) - bottom(local) - offset).norm(), 0.03);
  EXPECT_LT((top(shifted) - top(local) - offset).norm(), 0.1);
  EXPECT_NEAR(shifted.trunk[0].diameter, local.trunk[0].diameter, 0.003);
  EXPECT_NEAR(static_cast<double>(shifted.primary_branches.size()),
              static_cast<double>(local.primary_branches.size()), 3.0);
}

std::string realCloud(const char* name) {
  const std::string path = std::string(DTM_SHARED_DATA_DIR) + "/real/" + name;
  if (!std::filesystem::exists(path)) {
    if (std::getenv("CI"))
      ADD_FAILURE() << "missing shared data " << path;
    return {};
  }
  return path;
}

TEST(TreeModeler, RealTree1FindsATrunkQuickly) {
  const std::string path = realCloud("adtree_tree1.xyz");
  if (path.empty())
    GTEST_SKIP() << "../shared/data not present";
  const auto cloud = io::readCloud(path);
  const auto result = TreeModeler(ModelerConfig{}).model(*cloud.cloud);
  ASSERT_FALSE(result.model.trunk.empty());
  const auto& trunk = result.model.trunk;
  double length = 0.0;
  for (std::size_t i = 0; i < trunk.size(); ++i) {
    const auto& c = trunk[i];
    length += c.length;
    // A trunk run on past its fork into the crown ends in cylinders that hold 0-18 % of their
    // segment's points, standing 0.2-0.4 m off the trunk's axis among the stems.
    EXPECT_GT(c.inlier_ratio, 0.15) << "trunk cylinder at z " << c.center.z();
    if (i > 0) {
      const auto& below = trunk[i - 1];
      const Eigen::Vector3d w = c.center - below.center;
      EXPECT_LT((w - w.dot(below.axis) * below.axis).norm(), 0.05)
          << "trunk cylinder at z " << c.center.z() << " off the axis of the one below";
    }
  }
  EXPECT_GT(length, 1.0);
  EXPECT_LT(result.model.runtime_s, 10.0);
}

TEST(TreeModeler, RealTree13FinishesWithAModelOrTheNoTrunkError) {
  // Sparse and noisy (6,991 points over 10 m): today the modeler reports no_trunk here (see the
  // issue notes); what must hold is a clean, documented outcome.
  const std::string path = realCloud("adtree_tree13.xyz");
  if (path.empty())
    GTEST_SKIP() << "../shared/data not present";
  const auto cloud = io::readCloud(path);
  try {
    const auto result = TreeModeler(ModelerConfig{}).model(*cloud.cloud);
    EXPECT_FALSE(result.model.trunk.empty());
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::NO_TRUNK) << e.what();
  }
}

}  // namespace
}  // namespace modeling
}  // namespace dormant_tree_modeling
