#include "dormant_tree_modeling/simulation/dataset.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <chrono>
#include <cstdio>
#include <filesystem>
#include <nlohmann/json.hpp>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/io/point_cloud_io.h"
#include "dormant_tree_modeling/io/pose_json.h"
#include "dormant_tree_modeling/io/tree_json.h"
#include "dormant_tree_modeling/simulation/preview.h"
#include "dormant_tree_modeling/simulation/ray_caster.h"
#include "dormant_tree_modeling/simulation/view_simulator.h"

namespace dormant_tree_modeling {
namespace simulation {

namespace {

/// Axis-aligned box of the true tree (trunk and primaries) grown by a margin.
void truthBox(const evaluation::GroundTruth& truth, double margin, Eigen::Vector3d& lo,
              Eigen::Vector3d& hi) {
  lo = Eigen::Vector3d::Constant(1e9);
  hi = -lo;
  auto grow = [&](const evaluation::Polyline& p) {
    for (const auto& q : p.points) {
      lo = lo.cwiseMin(q);
      hi = hi.cwiseMax(q);
    }
  };
  grow(truth.trunk);
  for (const auto& b : truth.primary_branches)
    grow(b);
  lo.array() -= margin;
  hi.array() += margin;
}

std::string viewName(int index) {
  char buf[32];
  std::snprintf(buf, sizeof(buf), "view_%02d", index);
  return buf;
}

}  // namespace

Eigen::Isometry3d randomPlatformError(Rng& rng, double max_translation, double max_yaw_deg) {
  const double r = max_translation * std::sqrt(rng.uniform());
  const double a = rng.uniform(0.0, 2.0 * M_PI);
  const double yaw = rng.uniform(-1.0, 1.0) * max_yaw_deg * M_PI / 180.0;
  // Evaluated in this order so a seed gives the same error on every compiler.
  const double z = rng.uniform(-0.05, 0.05);
  return geometry::platformPose(r * std::cos(a), r * std::sin(a), z, yaw);
}

// One pass over the view plan writing each view's files as it is simulated, so a dataset of
// 40 views never holds more than one view in memory.
DatasetSummary writeDataset(const DatasetConfig& options, const std::string& dir) {
  const auto start = std::chrono::steady_clock::now();
  const Orchard orchard = generateOrchard(options.orchard, options.seed);
  const auto plan = acquisition::makeViewPlan(options.plan);
  std::error_code ec;
  std::filesystem::create_directories(std::filesystem::path(dir) / "views", ec);
  if (ec)
    throw Error(ErrorCode::IO_FAILURE, "cannot create " + dir + ": " + ec.message());

  saveScene(orchard.scene, dir + "/scene.json");
  nlohmann::json truth_doc = nlohmann::json::parse(io::truthToJson(orchard.truth));
  truth_doc["generator"] = {{"preset", options.orchard.preset},
                            {"seed", options.seed},
                            {"range_noise_sigma_m", options.sensor.range_noise_sigma}};
  io::writeTextFile(dir + "/truth.json", truth_doc.dump(1) + "\n");

  const RayCaster caster(orchard.scene);
  const Lms111Model model(caster, options.sensor);

  // One initial-guess error per platform position, in the platform's own frame (odometry or an
  // operator misjudging where the platform stands): slide moves between its views are exact.
  std::vector<Eigen::Isometry3d> guess_error;
  Rng guess_rng = Rng::derive(options.seed, 3);
  nlohmann::json views_doc = nlohmann::json::array();
  auto merged = std::make_shared<Cloud>();
  DatasetSummary summary;
  for (const auto& v : plan) {
    while (static_cast<int>(guess_error.size()) <= v.platform_index) {
      guess_error.push_back(
          randomPlatformError(guess_rng, options.guess_max_translation, options.guess_max_yaw_deg));
    }
    const Eigen::Isometry3d stage = geometry::stagePose(v.platform, options.geometry, v.slide);
    const Eigen::Isometry3d guess_stage =
        geometry::stagePose(v.platform * guess_error[v.platform_index], options.geometry, v.slide);
    const SimulatedView sim = simulateView(model, stage, options.geometry, options.plan,
                                           options.seed, v.index, options.threads);
    // The tree and its surroundings lie in 0 <= phi < 180 deg; the rest looks behind the sensor.
    const CloudPtr local = acquisition::toCloud(sim.image, 0.0, M_PI);
    const std::string name = viewName(v.index);
    if (options.write_views) {
      writeRangePgm(dir + "/views/" + name + "_range.pgm", sim.image.rows, sim.image.cols,
                    sim.image.range.data());
      io::writeCloud(dir + "/views/" + name + ".pcd", *local);
    }
    const Eigen::Isometry3f to_tree = stage.cast<float>();
    for (const auto& p : local->points) {
      const Eigen::Vector3f q = to_tree * p.getVector3fMap();
      merged->push_back(pcl::PointXYZ(q.x(), q.y(), q.z()));
    }
    views_doc.push_back({{"index", v.index},
                         {"name", name},
                         {"side", v.side},
                         {"platform_index", v.platform_index},
                         {"slide", v.slide},
                         {"points", local->size()},
                         {"true_pose", io::poseToJson(stage)},
                         {"guess_pose", io::poseToJson(guess_stage)}});
  }
  summary.views = static_cast<int>(plan.size());
  const nlohmann::json views_file{
      {"format", "dormant_tree_views/1"},
      {"frame", "tree: origin at the target trunk base, z up, x along the row"},
      {"pose", "rotary_stage frame in the tree frame; a view's points are in rotary_stage"},
      {"rows", options.plan.linesPerView()},
      {"cols", options.sensor.beamCount()},
      {"theta_min_deg", options.plan.theta_min_deg},
      {"theta_step_deg", options.plan.theta_step_deg},
      {"phi_min_deg", options.sensor.start_angle_deg},
      {"phi_step_deg", options.sensor.angular_resolution_deg},
      {"views", views_doc}};
  io::writeTextFile(dir + "/views.json", views_file.dump(1) + "\n");

  io::writeCloud(dir + "/merged.pcd", *merged);
  io::writeCloud(dir + "/merged.ply", *merged);
  Eigen::Vector3d lo, hi;
  truthBox(orchard.truth, options.target_crop_margin, lo, hi);
  lo.z() = std::max(lo.z(), 0.05);  // the hand crop leaves the ground out
  Cloud target;
  for (const auto& p : merged->points) {
    const Eigen::Vector3d q = p.getVector3fMap().cast<double>();
    if ((q.array() >= lo.array()).all() && (q.array() <= hi.array()).all())
      target.push_back(p);
  }
  io::writeCloud(dir + "/target.pcd", target);
  renderPreview(target, orchard.truth, dir + "/preview.png");

  summary.merged_points = merged->size();
  summary.target_points = target.size();
  summary.primary_branches = static_cast<int>(orchard.truth.primary_branches.size());
  summary.simulate_seconds =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return summary;
}

}  // namespace simulation
}  // namespace dormant_tree_modeling
