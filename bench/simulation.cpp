// Simulation speed: rays per second through the BVH against a full orchard scene, the same
// rays through a loop over every primitive (the baseline the BVH replaces), and one full view
// (200 x 1080 beams, 7 rays per beam) on one core against the device's own 8 s / 4 s.
#include <benchmark/benchmark.h>

#include <cmath>

#include "dormant_tree_modeling/geometry/stage_kinematics.h"
#include "dormant_tree_modeling/simulation/orchard_generator.h"
#include "dormant_tree_modeling/simulation/ray_caster.h"
#include "dormant_tree_modeling/simulation/view_simulator.h"
#include "peak_memory.h"

using namespace dormant_tree_modeling;
using namespace dormant_tree_modeling::simulation;

namespace {

const Orchard& orchard() {
  static const Orchard o = generateOrchard(OrchardConfig{}, 1);
  return o;
}

std::vector<Ray> laserRays(int n) {
  std::vector<Ray> rays;
  Rng rng(7);
  const Eigen::Vector3d origin(0.0, -1.5, 1.5);
  for (int i = 0; i < n; ++i) {
    const double theta = rng.uniform(-M_PI / 4, M_PI / 4), phi = rng.uniform(0.0, M_PI);
    rays.push_back(Ray{origin, Eigen::Vector3d(std::sin(phi) * std::sin(theta),
                                               std::sin(phi) * std::cos(theta), -std::cos(phi))});
  }
  return rays;
}

void BM_RayCastBvh(benchmark::State& state) {
  const RayCaster caster(orchard().scene);
  const auto rays = laserRays(20000);
  std::size_t hits = 0;
  for (auto _ : state) {
    for (const auto& r : rays)
      hits += caster.cast(r, 1e-4, 21.0).has_value();
  }
  benchmark::DoNotOptimize(hits);
  state.SetItemsProcessed(state.iterations() * rays.size());
  state.counters["primitives"] = static_cast<double>(caster.size());
  bench::reportPeakMemory(state);
}
BENCHMARK(BM_RayCastBvh)->Unit(benchmark::kMillisecond);

void BM_RayCastEveryPrimitive(benchmark::State& state) {
  std::vector<Frustum> frusta;
  for (const auto& t : orchard().scene.trees) {
    for (const auto& b : t.branches) {
      for (std::size_t i = 0; i + 1 < b.points.size(); ++i) {
        frusta.push_back(Frustum{b.points[i], b.points[i + 1], b.radii[i], b.radii[i + 1]});
      }
    }
  }
  const auto rays = laserRays(200);
  std::size_t hits = 0;
  for (auto _ : state) {
    for (const auto& r : rays) {
      double best = 21.0;
      for (const auto& f : frusta) {
        if (const auto h = intersect(r, f, 1e-4, best))
          best = h->first;
      }
      hits += best < 21.0;
    }
  }
  benchmark::DoNotOptimize(hits);
  state.SetItemsProcessed(state.iterations() * rays.size());
  bench::reportPeakMemory(state);
}
BENCHMARK(BM_RayCastEveryPrimitive)->Unit(benchmark::kMillisecond);

void BM_SimulateFullView(benchmark::State& state) {
  const RayCaster caster(orchard().scene);
  Lms111Config config;
  config.angular_resolution_deg = state.range(0) == 25 ? 0.25 : 0.5;
  config.scan_frequency_hz = static_cast<double>(state.range(0));
  const Lms111Model model(caster, config);
  const acquisition::ViewPlanConfig sweep;
  const auto stage = geometry::stagePose(geometry::platformPose(0, -1.5, 1.5, M_PI / 2), {}, 0.0);
  int view = 0;
  for (auto _ : state) {
    const auto v = simulateView(model, stage, {}, sweep, 1, view++, /*threads=*/1);
    benchmark::DoNotOptimize(v.image.range.data());
  }
  state.counters["beams"] = sweep.linesPerView() * config.beamCount();
  state.counters["device_s"] = sweep.linesPerView() / config.scan_frequency_hz;
  bench::reportPeakMemory(state);
}
BENCHMARK(BM_SimulateFullView)->Arg(25)->Arg(50)->Unit(benchmark::kMillisecond)->Iterations(3);

}  // namespace

BENCHMARK_MAIN();
