#include "dormant_tree_modeling/simulation/orchard_generator.h"

#include <cmath>
#include <filesystem>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/random.h"
#include "dormant_tree_modeling/io/tree_json.h"
#include "dormant_tree_modeling/simulation/calibration_rig.h"

namespace dormant_tree_modeling {
namespace simulation {

Orchard generateOrchard(const OrchardConfig& config, std::uint64_t seed) {
  if (!(config.neighbour_spacing_min > 0.0) ||
      config.neighbour_spacing_max < config.neighbour_spacing_min || !(config.row_spacing > 1.0)) {
    throw Error(ErrorCode::INVALID_ARGUMENT,
                "orchard spacing: need 0 < neighbour_spacing_min <= neighbour_spacing_max and "
                "row_spacing > 1 m");
  }
  if (config.preset == CALIBRATION_RIG_PRESET) {
    Orchard rig = calibrationRig(seed);
    rig.scene.has_ground = config.ground;
    return rig;
  }
  const TreeConfig params = presetParams(config.preset);
  Rng rng = Rng::derive(seed, 1);
  Orchard orchard;
  Scene& scene = orchard.scene;
  scene.trees.push_back(generateTree(params, seed, Eigen::Vector3d::Zero()));
  orchard.truth = truthFromTree(scene.trees[0]);

  std::uint64_t next = 1;
  auto addTree = [&](const Eigen::Vector3d& base) {
    const std::uint64_t tree_seed = Rng::derive(seed, 100, next++).next();
    scene.trees.push_back(generateTree(params, tree_seed, base, rng.uniform(0.0, 2.0 * M_PI)));
  };
  double left = config.neighbour_spacing_min, right = left;
  if (config.neighbours) {
    left = rng.uniform(config.neighbour_spacing_min, config.neighbour_spacing_max);
    right = rng.uniform(config.neighbour_spacing_min, config.neighbour_spacing_max);
    addTree(Eigen::Vector3d(-left, rng.uniform(-0.03, 0.03), 0.0));
    addTree(Eigen::Vector3d(right, rng.uniform(-0.03, 0.03), 0.0));
  }
  if (config.other_rows) {
    for (const double y : {-config.row_spacing, config.row_spacing}) {
      const double x0 = rng.uniform(-0.5, 0.5);
      for (int i = -1; i <= 1; ++i)
        addTree(Eigen::Vector3d(x0 + 1.05 * i, y, 0.0));
    }
  }
  if (config.wires) {
    for (const double h : config.wire_heights) {
      Wire w;
      w.a = Eigen::Vector3d(-15.0, config.wire_offset_y, h + rng.uniform(-0.03, 0.03));
      w.b = Eigen::Vector3d(15.0, config.wire_offset_y, h + rng.uniform(-0.03, 0.03));
      w.radius = 0.5 * rng.uniform(config.wire_diameter_min, config.wire_diameter_max);
      scene.wires.push_back(w);
    }
  }
  if (config.post) {
    Post p;
    const double side = rng.bernoulli(0.5) ? -left : right;
    p.base = Eigen::Vector3d(0.5 * side, config.wire_offset_y + 0.08, 0.0);
    p.height = rng.uniform(3.0, 3.5);
    p.radius = 0.5 * rng.uniform(0.08, 0.12);
    scene.posts.push_back(p);
  }
  scene.has_ground = config.ground;
  return orchard;
}

SceneAndTruth sceneFromFileOrPreset(const std::string& scene_path, const std::string& preset,
                                    std::uint64_t seed) {
  SceneAndTruth out;
  if (!scene_path.empty()) {
    out.scene = loadScene(scene_path);
    const auto truth = std::filesystem::path(scene_path).parent_path() / "truth.json";
    if (std::filesystem::exists(truth))
      out.truth = io::readTruthFile(truth.string());
    return out;
  }
  OrchardConfig config;
  config.preset = preset;
  Orchard orchard = generateOrchard(config, seed);
  out.scene = std::move(orchard.scene);
  out.truth = std::move(orchard.truth);
  return out;
}

}  // namespace simulation
}  // namespace dormant_tree_modeling
