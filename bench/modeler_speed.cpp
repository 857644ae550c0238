// Modeler speed versus input size (100k, 300k, 1M points of a synthetic 40-view scan), ours
// and the paper's method side by side, with peak memory.
#include <benchmark/benchmark.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <filesystem>

#include "dormant_tree_modeling/io/point_cloud_io.h"
#include "dormant_tree_modeling/modeling/tree_modeler.h"
#include "dormant_tree_modeling/simulation/dataset.h"
#include "peak_memory.h"

using namespace dormant_tree_modeling;

namespace {

/// The merged 40-view scan of one tree and its surroundings (2.7 M points), made once.
const Cloud& merged() {
  static const CloudPtr cloud = [] {
    const std::string dir = (std::filesystem::temp_directory_path() / "dtm_speed_tree").string();
    if (!std::filesystem::exists(dir + "/merged.pcd")) {
      simulation::DatasetConfig o;
      o.seed = 7;
      o.write_views = false;
      simulation::writeDataset(o, dir);
    }
    return io::readCloud(dir + "/merged.pcd").cloud;
  }();
  return *cloud;
}

/// n points of the scan nearest to the tree (a crop grown until it holds n points).
Cloud crop(std::size_t n) {
  std::vector<std::pair<float, std::size_t>> by_distance;
  const Cloud& all = merged();
  for (std::size_t i = 0; i < all.size(); ++i) {
    const auto& p = all[i];
    if (p.z > 0.05f)
      by_distance.emplace_back(p.x * p.x + p.y * p.y, i);
  }
  n = std::min(n, by_distance.size());
  std::nth_element(by_distance.begin(), by_distance.begin() + n, by_distance.end());
  Cloud out;
  for (std::size_t i = 0; i < n; ++i)
    out.push_back(all[by_distance[i].second]);
  return out;
}

void runModel(benchmark::State& state, const Cloud& input, bool ours) {
  modeling::ModelerConfig config = modeling::ModelerConfig::paper();
  if (ours) {
    config = modeling::ModelerConfig{};
    config.calibration = modeling::loadSensorCalibration(std::string(DTM_CONFIG_DIR) +
                                                         "/calibration/lms111_model.yaml");
  }
  const modeling::TreeModeler modeler(config);
  std::size_t branches = 0;
  for (auto _ : state) {
    try {
      branches = modeler.model(input).model.primary_branches.size();
    } catch (const std::exception& e) {
      state.SkipWithError(e.what());
      break;
    }
  }
  state.counters["points"] = static_cast<double>(input.size());
  state.counters["branches"] = static_cast<double>(branches);
  bench::reportPeakMemory(state);
  state.SetLabel(ours ? "ours" : "paper");
}

void BM_Model(benchmark::State& state) {
  runModel(state, crop(static_cast<std::size_t>(state.range(0))), state.range(1) != 0);
}
BENCHMARK(BM_Model)
    ->ArgsProduct({{100000, 300000, 1000000}, {1, 0}})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(1);

/// The whole merged scan as registration writes it: the tree, its neighbours, posts, wires
/// and the ground (2.7 M points), not cropped.
void BM_ModelWholeScan(benchmark::State& state) {
  runModel(state, merged(), state.range(0) != 0);
}
BENCHMARK(BM_ModelWholeScan)->Arg(1)->Arg(0)->Unit(benchmark::kMillisecond)->Iterations(1);

}  // namespace

BENCHMARK_MAIN();
