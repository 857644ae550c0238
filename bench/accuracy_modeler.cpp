// Modeler accuracy across scanners: per sensor world (our LMS111 model and variants whose
// physics differs: no footprint widening, a wider beam, noise growing with range with more
// mixed pixels) and range noise (3, 6, 12 mm), seeded synthetic trees scanned with the paper's
// 40-view plan and modeled with no calibration (noise part only), the shipped calibration
// (config/calibration/lms111_model.yaml, made on our world) and the calibration made from that
// world's own rig scan (synth_tree --preset calibration_rig, calibrate_diameters); the paper's
// method on our world as the baseline, as published and with e_t and N_c chosen per tree by
// its F1 (paper-t: the best any tuning of those two reaches). Scored with docs/evaluation.md.
// Our world has the tuning trees (seeds 100..) the defaults were chosen on and held-out ones;
// the variant worlds have held-out trees only, and our world also scores tree variants
// (crooked leader, drooping or steep scaffolds, sparse or dense whorls): never tuned on.
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "dormant_tree_modeling/calibration/rig_calibration.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/evaluation/matching.h"
#include "dormant_tree_modeling/io/point_cloud_io.h"
#include "dormant_tree_modeling/io/tree_json.h"
#include "dormant_tree_modeling/modeling/tree_modeler.h"
#include "dormant_tree_modeling/simulation/calibration_rig.h"
#include "dormant_tree_modeling/simulation/dataset.h"
#include "dormant_tree_modeling/simulation/tree_generator.h"

using namespace dormant_tree_modeling;

namespace {

const std::vector<std::string> PRESETS{"young_tall_spindle", "mature_tall_spindle",
                                       "central_leader"};
constexpr std::uint64_t FIRST_SEED = 100;
constexpr std::uint64_t RIG_SEED = 1;

struct Options {
  int tuning = 4, held_out = 4, variant_trees = 2;
  std::string out = (std::filesystem::temp_directory_path() / "dtm_accuracy").string();
  std::vector<double> noise_mm{3.0, 6.0, 12.0};
  std::vector<std::string> worlds = simulation::sensorVariantNames();
  bool paper = true;  // the paper's method as the baseline in our world
};

std::vector<std::string> split(const std::string& text) {
  std::vector<std::string> out;
  std::stringstream ss(text);
  for (std::string t; std::getline(ss, t, ',');)
    out.push_back(t);
  return out;
}

constexpr const char* USAGE =
    "Usage: accuracy_modeler [--trees N (tuning, per preset, default 4)] [--held-out N (default "
    "4)] [--variant-trees N (per preset, default 2)] [--out DIR] [--noise-mm a,b,c] [--worlds "
    "ours,thin_beam,wide_beam,far_noise] [--no-paper (skip the paper's baseline, the slow "
    "part)]\n";

/// The options; usage on stdout and exit 0 for --help, on stderr and exit 2 for anything else
/// it does not know (an unknown option once ran the whole bench).
Options parse(int argc, char** argv) {
  Options o;
  for (int i = 1; i < argc; i += 2) {
    const std::string key = argv[i];
    if (key == "--help" || key == "-h") {
      std::cout << USAGE;
      std::exit(0);
    }
    if (key == "--no-paper") {
      o.paper = false;
      --i;  // a flag: no value follows
      continue;
    }
    if (i + 1 >= argc) {
      std::cerr << "accuracy_modeler: " << key << " needs a value\n" << USAGE;
      std::exit(2);
    }
    const std::string value = argv[i + 1];
    if (key == "--trees")
      o.tuning = std::stoi(value);
    else if (key == "--held-out")
      o.held_out = std::stoi(value);
    else if (key == "--variant-trees")
      o.variant_trees = std::stoi(value);
    else if (key == "--out")
      o.out = value;
    else if (key == "--worlds")
      o.worlds = split(value);
    else if (key == "--noise-mm") {
      o.noise_mm.clear();
      for (const auto& t : split(value))
        o.noise_mm.push_back(std::stod(t));
    } else {
      std::cerr << "accuracy_modeler: unknown option " << key << "\n" << USAGE;
      std::exit(2);
    }
  }
  return o;
}

/// The scan of a preset and seed in a world at a noise, simulated once into `dir`.
void ensureDataset(const std::string& preset, std::uint64_t seed, const std::string& world,
                   double noise_mm, const std::string& dir) {
  if (std::filesystem::exists(dir + "/target.pcd"))
    return;
  simulation::DatasetConfig o;
  o.orchard.preset = preset;
  o.seed = seed;
  o.sensor = simulation::sensorVariant(world);
  o.sensor.range_noise_sigma = noise_mm / 1000.0;
  o.write_views = false;
  simulation::writeDataset(o, dir);
}

/// The world's own calibration: its rig scanned at this noise, measured by calibrate_diameters'
/// procedure.
modeling::SensorCalibration rigCalibration(const std::string& world, double noise_mm,
                                           const std::string& out) {
  char name[128];
  std::snprintf(name, sizeof(name), "%s/%s/rig_%gmm", out.c_str(), world.c_str(), noise_mm);
  ensureDataset(simulation::CALIBRATION_RIG_PRESET, RIG_SEED, world, noise_mm, name);
  calibration::RigScan scan;
  scan.name = name;
  scan.points = io::readPointsInFileFrame(std::string(name) + "/target.pcd");
  scan.rig = io::readTruthFile(std::string(name) + "/truth.json");
  const auto result =
      calibration::calibrateFromRig({scan}, modeling::ModelerConfig{}, world + "_rig");
  for (const auto& w : result.warnings)
    std::cerr << "rig " << name << ": " << w << "\n";
  return result.calibration;
}

// The paper's two parameters a user tunes to a tree (e_t, graph.split_error_m, and the points
// per cluster, graph.points_per_cluster, N = points / N_c): the paper's values first, then
// values for centimetre noise and for finer clusters.
const std::vector<double> PAPER_SPLIT_ERRORS_M{0.004, 0.015, 0.025};
const std::vector<int> PAPER_POINTS_PER_CLUSTER{3000, 800};

/// The configurations compared: the paper's method as published and tuned per tree, ours
/// without, with the shipped and with the world's own calibration. A method of several
/// configurations scores each tree by the one with the best F1 on it.
struct Method {
  std::string name;
  std::vector<modeling::ModelerConfig> configs;
};

/// The paper's method on every point of its parameter grid.
std::vector<modeling::ModelerConfig> paperGrid() {
  std::vector<modeling::ModelerConfig> grid;
  for (const double e_t : PAPER_SPLIT_ERRORS_M) {
    for (const int n_c : PAPER_POINTS_PER_CLUSTER) {
      grid.push_back(modeling::ModelerConfig::paper());
      grid.back().graph.split_error_m = e_t;
      grid.back().graph.points_per_cluster = n_c;
    }
  }
  return grid;
}

std::vector<Method> methods(const modeling::SensorCalibration& shipped,
                            const modeling::SensorCalibration& own, bool with_paper) {
  std::vector<Method> m;
  if (with_paper) {
    m.push_back({"paper", {modeling::ModelerConfig::paper()}});
    m.push_back({"paper-t", paperGrid()});
  }
  m.push_back({"none", {modeling::ModelerConfig{}}});
  m.push_back({"shipped", {modeling::ModelerConfig{}}});
  m.back().configs.front().calibration = shipped;
  m.push_back({"rig", {modeling::ModelerConfig{}}});
  m.back().configs.front().calibration = own;
  return m;
}

evaluation::TreeScore scoreTree(const modeling::TreeModeler& modeler, const modeling::Points& cloud,
                                const evaluation::GroundTruth& truth, const std::string& name) {
  try {
    return evaluation::evaluate(modeler.model(cloud).model, truth);
  } catch (const Error& e) {
    // A tree the method cannot model scores as all branches missed.
    evaluation::TreeScore s;
    s.pb = s.fn = static_cast<int>(truth.primary_branches.size());
    s.fn_rate = 1.0;
    std::cerr << name << ": " << e.what() << "\n";
    return s;
  }
}

/// A tree's score under the best of a method's configurations (by F1).
evaluation::TreeScore bestScore(const std::vector<modeling::TreeModeler>& modelers,
                                const modeling::Points& cloud, const evaluation::GroundTruth& truth,
                                const std::string& name) {
  evaluation::TreeScore best;
  best.f1 = -1.0;
  for (const auto& modeler : modelers) {
    evaluation::TreeScore s = scoreTree(modeler, cloud, truth, name);
    if (s.f1 > best.f1)
      best = std::move(s);
  }
  return best;
}

std::string summary(const std::string& world, double noise, const char* set,
                    const std::vector<Method>& ms,
                    const std::vector<std::vector<evaluation::TreeScore>>& scores) {
  char head[96];
  std::snprintf(head, sizeof(head), "%-10s %4.0f mm %-8s", world.c_str(), noise, set);
  std::string line = head;
  for (std::size_t k = 0; k < ms.size(); ++k) {
    const auto m = evaluation::meanScore(scores[k]);
    char part[192];
    std::snprintf(part, sizeof(part),
                  " | %-7s F1 %6.2f%% br %5.2f (%+5.2f) unmeas %3.0f%% tr %5.2f",
                  ms[k].name.c_str(), 100 * m.f1, 1000 * m.branch_mae, 1000 * m.branch_bias,
                  m.tp > 0 ? 100.0 * m.unresolved / m.tp : 0.0, 1000 * m.trunk_mae);
    line += part;
  }
  return line;
}

}  // namespace

int main(int argc, char** argv) {
  const Options opt = parse(argc, argv);
  const auto shipped = modeling::loadSensorCalibration(std::string(DTM_CONFIG_DIR) +
                                                       "/calibration/lms111_model.yaml");
  std::vector<std::string> lines;
  for (const double noise : opt.noise_mm) {
    for (const auto& world : opt.worlds) {
      const auto own = rigCalibration(world, noise, opt.out);
      const bool ours = world == "ours";
      const auto ms = methods(shipped, own, ours && opt.paper);
      std::vector<std::vector<modeling::TreeModeler>> modelers(ms.size());
      for (std::size_t m = 0; m < ms.size(); ++m) {
        for (const auto& config : ms[m].configs)
          modelers[m].emplace_back(config);
      }
      struct Set {
        const char* name;
        int first, count;
        std::vector<std::string> presets;
      };
      const std::vector<Set> sets =
          ours ? std::vector<Set>{{"tuning", 0, opt.tuning, PRESETS},
                                  {"held-out", opt.tuning, opt.held_out, PRESETS},
                                  {"tree-var", opt.tuning, opt.variant_trees,
                                   simulation::variantPresetNames()}}
               : std::vector<Set>{{"scored", opt.tuning, opt.variant_trees, PRESETS}};
      for (const Set& set : sets) {
        if (set.count <= 0)
          continue;
        std::vector<std::vector<evaluation::TreeScore>> scores(ms.size());
        for (const auto& preset : set.presets) {
          for (int k = set.first; k < set.first + set.count; ++k) {
            char name[160];
            std::snprintf(name, sizeof(name), "%s/%s/%s_%02d_%gmm", opt.out.c_str(), world.c_str(),
                          preset.c_str(), k, noise);
            ensureDataset(preset, FIRST_SEED + k, world, noise, name);
            const auto cloud = io::readPointsInFileFrame(std::string(name) + "/target.pcd");
            const auto truth = io::readTruthFile(std::string(name) + "/truth.json");
            for (std::size_t m = 0; m < ms.size(); ++m) {
              scores[m].push_back(bestScore(modelers[m], cloud, truth, name));
              scores[m].back().name = name;
            }
            std::cerr << "." << std::flush;
          }
        }
        std::cerr << "\n";
        std::cout << "\n=== " << world << ", range noise " << noise << " mm, " << set.name
                  << " trees, calibration from the world's rig ===\n"
                  << evaluation::formatTable(scores.back());
        lines.push_back(summary(world, noise, set.name, ms, scores));
        std::cout << lines.back() << "\n" << std::flush;
      }
    }
  }
  std::cout << "\n=== summary: F1, branch diameter MAE (bias) in mm, the share of matched branches "
               "whose diameter was not measured (at the floor, or a reading thinner branches give "
               "too), trunk MAE in mm; "
               "targets with the rig's calibration: branch MAE <= 3 mm and |bias| <= 1 mm at 3 "
               "and 6 mm, <= 4.5 mm at 12 mm; trunk MAE <= 2.5 mm; F1 >= 98% ===\n";
  for (const auto& l : lines)
    std::cout << l << "\n";
  return 0;
}
