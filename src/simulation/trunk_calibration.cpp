#include "dormant_tree_modeling/simulation/trunk_calibration.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cmath>

#include "dormant_tree_modeling/acquisition/range_image.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/statistics.h"
#include "dormant_tree_modeling/modeling/trunk_model.h"
#include "dormant_tree_modeling/simulation/ray_caster.h"
#include "dormant_tree_modeling/simulation/view_simulator.h"

namespace dormant_tree_modeling {
namespace simulation {

namespace {

constexpr double BAND_MARGIN = 0.05;  // m at each band end left out: the radius steps there
constexpr double CROP_RADIUS = 0.3;   // m around the pole's axis

/// A vertical pole at the tree's place whose radius steps through `radii`, one band each.
Scene poleScene(const std::vector<double>& radii, const TrunkCalibrationOptions& o) {
  BranchPolyline pole;
  pole.part = Part::TRUNK;
  for (std::size_t i = 0; i < radii.size(); ++i) {
    const double z0 = o.base_height + i * o.band_height;
    // Short transitions between bands, so the pole is one continuous surface.
    pole.points.emplace_back(0.0, 0.0, i == 0 ? 0.0 : z0 + 0.01);
    pole.radii.push_back(radii[i]);
    pole.points.emplace_back(0.0, 0.0, z0 + o.band_height - 0.01);
    pole.radii.push_back(radii[i]);
  }
  TreeObject tree;
  tree.preset = "calibration_pole";
  tree.branches.push_back(pole);
  Scene scene;
  scene.trees.push_back(tree);
  return scene;
}

}  // namespace

std::vector<Eigen::Vector3d> scanReferenceScene(const Scene& scene, double noise,
                                                const TrunkCalibrationOptions& o,
                                                std::uint64_t seed, double crop_radius) {
  const RayCaster caster(scene);
  Lms111Config sensor = o.sensor;
  sensor.range_noise_sigma = noise;
  const Lms111Model model(caster, sensor);
  std::vector<Eigen::Vector3d> pts;
  for (const auto& v : acquisition::makeViewPlan(o.plan)) {
    const Eigen::Isometry3d stage = acquisition::stagePose(v.platform, o.geometry, v.slide);
    const SimulatedView sim =
        simulateView(model, stage, o.geometry, o.plan, seed, v.index, o.threads);
    const auto local = acquisition::toCloud(sim.image, 0.0, M_PI);
    for (const auto& p : local->points) {
      const Eigen::Vector3d q = stage * p.getVector3fMap().cast<double>();
      if (std::hypot(q.x(), q.y()) < crop_radius && q.z() > 0.05)
        pts.push_back(q);
    }
  }
  return pts;
}

void checkCalibrationAxes(const TrunkCalibrationOptions& o) {
  auto usable = [](const std::vector<double>& v) {
    return !v.empty() && v.front() > 0.0 && modeling::strictlyAscending(v);
  };
  if (!usable(o.radii) || !usable(o.noise))
    throw Error(ErrorCode::INVALID_ARGUMENT,
                "calibration radii and noise levels must be positive and ascending");
}

void appendCalibrationRow(modeling::RadiusCalibration& table, std::vector<double> bias,
                          const std::vector<char>& measured, double noise_axis) {
  const std::vector<double> raw = bias;
  for (std::size_t k = 0; k < bias.size(); ++k) {
    if (measured[k])
      continue;
    for (std::size_t d = 1; d < bias.size(); ++d) {
      if (k >= d && measured[k - d]) {
        bias[k] = raw[k - d];
        break;
      }
      if (k + d < bias.size() && measured[k + d]) {
        bias[k] = raw[k + d];
        break;
      }
    }
  }
  if (!table.noise.empty())
    noise_axis = std::max(noise_axis, table.noise.back() + 1e-5);
  table.noise.push_back(noise_axis);
  table.bias.insert(table.bias.end(), bias.begin(), bias.end());
}

TrunkCalibrationResult calibrateTrunkRadii(const TrunkCalibrationOptions& o) {
  checkCalibrationAxes(o);
  modeling::ModelerConfig config = o.modeler;
  config.trunk_calibration = {};
  config.ours_correct_noise_bias = true;
  config.noise_sigma = -1.0;

  TrunkCalibrationResult result;
  result.calibration.radii = o.radii;
  const std::vector<double> descending(o.radii.rbegin(), o.radii.rend());
  for (std::size_t level = 0; level < o.noise.size(); ++level) {
    const double noise = o.noise[level];
    std::vector<std::vector<double>> apparent(o.radii.size()), estimate(o.radii.size());
    int order = 0;
    for (const auto* radii : {&o.radii, &descending}) {
      const modeling::Points pts = scanReferenceScene(
          poleScene(*radii, o), noise, o, o.seed * 1000 + level * 2 + order++, CROP_RADIUS);
      for (std::size_t b = 0; b < radii->size(); ++b) {
        const double r = (*radii)[b];
        const double z0 = o.base_height + b * o.band_height + BAND_MARGIN;
        const double z1 = o.base_height + (b + 1) * o.band_height - BAND_MARGIN;
        std::vector<int> region;
        for (std::size_t i = 0; i < pts.size(); ++i) {
          if (pts[i].z() >= z0 && pts[i].z() < z1)
            region.push_back(static_cast<int>(i));
        }
        const std::size_t k = std::lower_bound(o.radii.begin(), o.radii.end(), r) - o.radii.begin();
        try {
          const auto trunk = modeling::modelTrunk(
              pts, region, {Eigen::Vector3d(0, 0, z0), Eigen::Vector3d(0, 0, z1)}, r, config);
          std::vector<double> radii_seen;
          for (const auto& sl : trunk.slices) {
            if (sl.has_circle)
              radii_seen.push_back(sl.corrected_radius);
          }
          if (!radii_seen.empty()) {
            apparent[k].push_back(median(radii_seen));
            estimate[k].push_back(trunk.noise_sigma);
          }
        } catch (const Error&) {
          // A band too thin to measure at this noise: left out, the table holds its neighbour.
        }
      }
    }
    double sigma_sum = 0.0;
    int sigma_n = 0;
    std::vector<double> row(o.radii.size(), 0.0);
    std::vector<char> measured(o.radii.size(), 0);
    for (std::size_t k = 0; k < o.radii.size(); ++k) {
      if (apparent[k].empty())
        continue;
      CalibrationSample s;
      s.radius = o.radii[k];
      s.sensor_noise = noise;
      for (std::size_t j = 0; j < apparent[k].size(); ++j) {
        s.apparent += apparent[k][j] / apparent[k].size();
        s.noise_estimate += estimate[k][j] / estimate[k].size();
      }
      row[k] = s.apparent - s.radius;
      measured[k] = 1;
      if (s.noise_estimate > 0.0) {
        sigma_sum += s.noise_estimate;
        ++sigma_n;
      }
      result.samples.push_back(s);
    }
    appendCalibrationRow(result.calibration, row, measured,
                         sigma_n > 0 ? sigma_sum / sigma_n : noise);
  }
  return result;
}

}  // namespace simulation
}  // namespace dormant_tree_modeling
