// Modeler accuracy: seeded synthetic trees across the presets, scanned with the paper's
// 40-view plan at range noise 3, 6 and 12 mm, modeled with the paper's method and with ours,
// scored with docs/evaluation.md, printed as the paper's Table 3 per noise level.
// Two sets of trees: the tuning set (seeds 100..) that the modeler's defaults were chosen on,
// and a held-out set (the seeds after it) that is only scored, so that what the table
// promises holds for trees the parameters never saw.
// Usage: accuracy_modeler [--trees N (tuning, per preset, default 4)]
//                         [--held-out N (per preset, default 4)] [--out DIR] [--noise-mm a,b,c]
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cstdio>
#include <cstring>
#include <filesystem>
#include <iostream>
#include <sstream>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/evaluation/matching.h"
#include "dormant_tree_modeling/io/point_cloud_io.h"
#include "dormant_tree_modeling/io/tree_json.h"
#include "dormant_tree_modeling/modeling/tree_modeler.h"
#include "dormant_tree_modeling/simulation/dataset.h"

using namespace dormant_tree_modeling;

int main(int argc, char** argv) {
  int per_preset = 4;
  int held_out = 4;
  std::string out = (std::filesystem::temp_directory_path() / "dtm_accuracy").string();
  std::vector<double> noises{3.0, 6.0, 12.0};
  for (int i = 1; i + 1 < argc; i += 2) {
    if (!std::strcmp(argv[i], "--trees"))
      per_preset = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--held-out"))
      held_out = std::atoi(argv[i + 1]);
    if (!std::strcmp(argv[i], "--out"))
      out = argv[i + 1];
    if (!std::strcmp(argv[i], "--noise-mm")) {
      noises.clear();
      std::stringstream ss(argv[i + 1]);
      for (std::string t; std::getline(ss, t, ',');)
        noises.push_back(std::stod(t));
    }
  }
  const std::vector<std::string> presets{"young_tall_spindle", "mature_tall_spindle",
                                         "central_leader"};
  struct TreeSet {
    const char* name;
    int first, count;  // seed offsets from 100
  };
  const std::vector<TreeSet> sets{{"tuning", 0, per_preset}, {"held-out", per_preset, held_out}};
  std::vector<std::string> summary;
  for (const double noise : noises) {
    for (const TreeSet& set : sets) {
      if (set.count <= 0)
        continue;
      std::vector<evaluation::TreeScore> paper, ours;
      for (const auto& preset : presets) {
        for (int k = set.first; k < set.first + set.count; ++k) {
          const std::uint64_t seed = 100 + k;
          char name[96];
          std::snprintf(name, sizeof(name), "%s_%02d_%gmm", preset.c_str(), k, noise);
          const std::string dir = out + "/" + name;
          simulation::DatasetOptions o;
          o.orchard.preset = preset;
          o.seed = seed;
          o.sensor.range_noise_sigma = noise / 1000.0;
          o.write_views = false;
          if (!std::filesystem::exists(dir + "/target.pcd"))
            simulation::writeDataset(o, dir);
          const auto cloud = io::readCloud(dir + "/target.pcd");
          const auto truth = io::readTruthFile(dir + "/truth.json");
          for (const bool is_ours : {false, true}) {
            const modeling::TreeModeler modeler(is_ours ? modeling::ModelerConfig{}
                                                        : modeling::ModelerConfig::paper());
            evaluation::TreeScore s;
            try {
              const auto result = modeler.model(*cloud.cloud);
              io::writeTextFile(dir + (is_ours ? "/model_ours.json" : "/model_paper.json"),
                                io::modelToJson(result.model));
              s = evaluation::evaluate(result.model, truth);
            } catch (const Error& e) {
              // A tree the method cannot model scores as all branches missed.
              s.pb = static_cast<int>(truth.primary_branches.size());
              s.fn = s.pb;
              s.fn_rate = 1.0;
              std::cerr << name << (is_ours ? " ours: " : " paper: ") << e.what() << "\n";
            }
            s.name = name;
            (is_ours ? ours : paper).push_back(s);
          }
          std::cerr << "." << std::flush;
        }
      }
      std::cerr << "\n";
      std::cout << "\n=== range noise " << noise << " mm, " << set.name
                << " trees, paper's method (Algorithms 2 and 3) ===\n"
                << evaluation::formatTable(paper);
      std::cout << "\n=== range noise " << noise << " mm, " << set.name << " trees, ours ===\n"
                << evaluation::formatTable(ours);
      const auto mp = evaluation::meanScore(paper), mo = evaluation::meanScore(ours);
      char line[320];
      std::snprintf(line, sizeof(line),
                    "%5.1f mm %-8s paper F1 %6.2f%%  br MAE %5.2f mm  tr MAE %5.2f mm | ours F1 "
                    "%6.2f%%  br MAE %5.2f mm  br bias %+5.2f mm  tr MAE %5.2f mm",
                    noise, set.name, 100 * mp.f1, 1000 * mp.branch_mae, 1000 * mp.trunk_mae,
                    100 * mo.f1, 1000 * mo.branch_mae, 1000 * mo.branch_bias, 1000 * mo.trunk_mae);
      summary.emplace_back(line);
    }
  }
  std::cout << "\n=== summary (targets: F1 >= 98%, branch MAE <= 6 mm, trunk MAE <= 3 mm) ===\n";
  for (const auto& s : summary)
    std::cout << s << "\n";
  return 0;
}
