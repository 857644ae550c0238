#include "dormant_tree_modeling/simulation/branch_calibration.h"

#include <Eigen/Geometry>
#include <cmath>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/evaluation/matching.h"
#include "dormant_tree_modeling/modeling/tree_modeler.h"

namespace dormant_tree_modeling {
namespace simulation {

namespace {

constexpr double POLE_RADIUS = 0.025;  // m
constexpr double POLE_HEIGHT = 3.2;    // m
constexpr double ROD_LENGTH = 0.6;     // m
constexpr int RODS_PER_RADIUS = 3;
constexpr double LOWEST_ROD = 0.7;   // m
constexpr double HIGHEST_ROD = 2.9;  // m
constexpr double CROP_RADIUS = 1.0;  // m
const double ELEVATIONS_DEG[] = {-10.0, 10.0, 30.0};

/// The reference tree: rods in the given order up the pole, a golden-angle turn apart.
Scene referenceTree(const std::vector<double>& rod_radii, evaluation::GroundTruth* truth) {
  TreeObject tree;
  tree.preset = "branch_calibration";
  BranchPolyline pole;
  pole.points = {Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 0, POLE_HEIGHT)};
  pole.radii = {POLE_RADIUS, POLE_RADIUS};
  tree.branches.push_back(pole);
  truth->trunk.points = pole.points;
  truth->trunk.diameters = {2 * POLE_RADIUS, 2 * POLE_RADIUS};
  const int n = static_cast<int>(rod_radii.size());
  for (int i = 0; i < n; ++i) {
    const double z = LOWEST_ROD + (HIGHEST_ROD - LOWEST_ROD) * i / std::max(1, n - 1);
    const double azimuth = i * 137.508 * M_PI / 180.0;
    const double elevation = ELEVATIONS_DEG[i % 3] * M_PI / 180.0;
    const Eigen::Vector3d dir(std::cos(elevation) * std::cos(azimuth),
                              std::cos(elevation) * std::sin(azimuth), std::sin(elevation));
    BranchPolyline rod;
    rod.part = Part::PRIMARY;
    rod.parent = 0;
    const Eigen::Vector3d base(0, 0, z);
    rod.points = {base, base + ROD_LENGTH * dir};
    rod.radii = {rod_radii[i], rod_radii[i]};
    tree.branches.push_back(rod);
    evaluation::Polyline line;
    line.id = i;
    line.points = rod.points;
    line.diameters = {2 * rod_radii[i], 2 * rod_radii[i]};
    truth->primary_branches.push_back(line);
  }
  Scene scene;
  scene.trees.push_back(tree);
  return scene;
}

}  // namespace

std::vector<double> defaultBranchCalibrationRadii() {
  return {0.003, 0.004, 0.005, 0.0065, 0.008, 0.01, 0.0125, 0.015, 0.02};
}

TrunkCalibrationResult calibrateBranchRadii(const TrunkCalibrationOptions& o) {
  checkCalibrationAxes(o);
  modeling::ModelerConfig config = o.modeler;
  config.branch_calibration = {};
  config.branch_raw_radius = true;
  config.ours_correct_noise_bias = true;
  config.noise_sigma = -1.0;
  const modeling::TreeModeler modeler(config);

  // Each radius several times, interleaved so that every radius is seen low and high.
  std::vector<double> order;
  for (int k = 0; k < RODS_PER_RADIUS; ++k) {
    for (std::size_t i = 0; i < o.radii.size(); ++i)
      order.push_back(o.radii[(i + 3 * k) % o.radii.size()]);
  }
  TrunkCalibrationResult result;
  result.calibration.radii = o.radii;
  for (std::size_t level = 0; level < o.noise.size(); ++level) {
    std::vector<double> sum(o.radii.size(), 0.0);
    std::vector<int> count(o.radii.size(), 0);
    double sigma_sum = 0.0;
    int sigma_n = 0;
    for (int pass = 0; pass < 2; ++pass) {
      std::vector<double> radii = order;
      if (pass == 1)
        std::reverse(radii.begin(), radii.end());
      evaluation::GroundTruth truth;
      const Scene scene = referenceTree(radii, &truth);
      const auto pts = scanReferenceScene(scene, o.noise[level], o,
                                          o.seed * 2000 + level * 2 + pass, CROP_RADIUS);
      const auto model = modeler.model(pts);
      sigma_sum += model.noise_sigma;
      ++sigma_n;
      const auto score = evaluation::evaluate(model.model, truth);
      for (const auto& m : score.matches) {
        const double r = radii[m.truth];
        const std::size_t k =
            std::lower_bound(o.radii.begin(), o.radii.end(), r - 1e-12) - o.radii.begin();
        sum[k] += 0.5 * m.detected_diameter;
        ++count[k];
      }
    }
    std::vector<double> row(o.radii.size(), 0.0);
    std::vector<char> measured(o.radii.size(), 0);
    for (std::size_t k = 0; k < o.radii.size(); ++k) {
      if (count[k] == 0)
        continue;
      CalibrationSample s;
      s.radius = o.radii[k];
      s.sensor_noise = o.noise[level];
      s.apparent = sum[k] / count[k];
      s.noise_estimate = sigma_sum / sigma_n;
      row[k] = s.apparent - s.radius;
      measured[k] = 1;
      result.samples.push_back(s);
    }
    appendCalibrationRow(result.calibration, row, measured, sigma_sum / sigma_n);
  }
  return result;
}

}  // namespace simulation
}  // namespace dormant_tree_modeling
