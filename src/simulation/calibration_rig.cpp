#include "dormant_tree_modeling/simulation/calibration_rig.h"

#include <cmath>

#include "dormant_tree_modeling/common/random.h"

namespace dormant_tree_modeling {
namespace simulation {

namespace {

struct PipeSection {
  double diameter_m;
  double height_m;
};
// Bottom to top; the rods leave the fourth section.
const PipeSection PIPE[] = {{0.200, 0.35}, {0.140, 0.35}, {0.100, 0.35}, {0.060, 1.60},
                            {0.040, 0.35}, {0.025, 0.30}, {0.016, 0.30}};
constexpr int ROD_SECTION = 3;
constexpr double STEP_M = 0.002;  // a section's end to the next one's start
const double ROD_DIAMETERS_M[] = {0.004, 0.006, 0.008, 0.010, 0.013,
                                  0.016, 0.020, 0.025, 0.030, 0.040};
constexpr int RODS_PER_DIAMETER = 2;
constexpr double ROD_LENGTH_M = 0.5;
constexpr double ROD_MARGIN_M = 0.1;  // rod-free pipe at both ends of its section
const double ROD_ELEVATIONS_DEG[] = {0.0, 20.0, 35.0};
constexpr double GOLDEN_ANGLE_DEG = 137.508;

/// The pipe as one polyline: each section's bottom and top, the next section 2 mm higher.
BranchPolyline pipe(double* rod_lo, double* rod_hi) {
  BranchPolyline p;
  double z = 0.0;
  int k = 0;
  for (const auto& s : PIPE) {
    p.points.emplace_back(0.0, 0.0, k == 0 ? z : z + STEP_M);
    p.points.emplace_back(0.0, 0.0, z + s.height_m);
    p.radii.insert(p.radii.end(), 2, 0.5 * s.diameter_m);
    if (k == ROD_SECTION) {
      *rod_lo = z + ROD_MARGIN_M;
      *rod_hi = z + s.height_m - ROD_MARGIN_M;
    }
    z += s.height_m;
    ++k;
  }
  return p;
}

}  // namespace

Orchard calibrationRig(std::uint64_t seed) {
  Orchard rig;
  TreeObject tree;
  tree.preset = CALIBRATION_RIG_PRESET;
  tree.seed = seed;
  double lo = 0.0, hi = 0.0;
  tree.branches.push_back(pipe(&lo, &hi));
  evaluation::GroundTruth& truth = rig.truth;
  truth.trunk.points = tree.branches[0].points;
  for (const double r : tree.branches[0].radii)
    truth.trunk.diameters.push_back(2.0 * r);
  // Each diameter low and high: diameters ascending, then descending.
  std::vector<double> order;
  const int kinds = static_cast<int>(std::size(ROD_DIAMETERS_M));
  for (int pass = 0; pass < RODS_PER_DIAMETER; ++pass) {
    for (int i = 0; i < kinds; ++i)
      order.push_back(ROD_DIAMETERS_M[pass % 2 ? kinds - 1 - i : i]);
  }
  Rng rng = Rng::derive(seed, 7);
  const double turn = rng.uniform(0.0, 360.0);
  const int n = static_cast<int>(order.size());
  for (int i = 0; i < n; ++i) {
    const double z = lo + (hi - lo) * i / (n - 1);
    const double azimuth = (turn + i * GOLDEN_ANGLE_DEG) * M_PI / 180.0;
    const double elevation = ROD_ELEVATIONS_DEG[i % 3] * M_PI / 180.0;
    const Eigen::Vector3d dir(std::cos(elevation) * std::cos(azimuth),
                              std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
    BranchPolyline rod;
    rod.part = Part::PRIMARY;
    rod.parent = 0;
    rod.points = {Eigen::Vector3d(0, 0, z), Eigen::Vector3d(0, 0, z) + ROD_LENGTH_M * dir};
    rod.radii = {0.5 * order[i], 0.5 * order[i]};
    tree.branches.push_back(rod);
    evaluation::Polyline line;
    line.id = i;
    line.points = rod.points;
    line.diameters = {order[i], order[i]};
    truth.primary_branches.push_back(line);
  }
  rig.scene.trees.push_back(tree);
  rig.scene.has_ground = true;
  return rig;
}

}  // namespace simulation
}  // namespace dormant_tree_modeling
