#pragma once
// Built (noise-free, evenly spread) scenes for the modeling tests.

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include "dormant_tree_modeling/modeling/modeler_config.h"
#include "dormant_tree_modeling/modeling/tree_modeler.h"
#include "dormant_tree_modeling/modeling/trunk_model.h"

namespace dormant_tree_modeling {
namespace test {

using modeling::ModelerConfig;
using modeling::Points;
using modeling::TrunkModel;

/// Points on a cylinder surface, evenly spread (a fixture, not a statistic).
inline void addCylinder(Points& pts, const Eigen::Vector3d& base, const Eigen::Vector3d& axis,
                        double r, double length, double step = 0.005) {
  const Eigen::Vector3d a = axis.normalized(), u = a.unitOrthogonal(), v = a.cross(u);
  const int rings = static_cast<int>(std::lround(length / step)),
            around = std::max(8, static_cast<int>(2 * M_PI * r / step));
  for (int i = 0; i <= rings; ++i) {
    for (int k = 0; k < around; ++k) {
      const double phi = 2.0 * M_PI * k / around;
      pts.push_back(base + i * step * a + r * (std::cos(phi) * u + std::sin(phi) * v));
    }
  }
}

/// Every point moved by isotropic Gaussian noise of `sigma` (m), seeded.
inline void addIsotropicNoise(Points& pts, double sigma, unsigned seed) {
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0.0, sigma);
  for (auto& p : pts)
    p += Eigen::Vector3d(noise(rng), noise(rng), noise(rng));
}

/// The angle between two lines (undirected), in degrees.
inline double lineAngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return std::acos(std::min(1.0, std::abs(a.normalized().dot(b.normalized())))) * 180.0 / M_PI;
}

/// The trunk of a built scene: its first trunk_points points, a vertical 3 cm cylinder from
/// z 0 to 1.5 m, modeled at 2 mm noise.
struct BuiltTrunk {
  std::vector<int> region;
  ModelerConfig config;
  TrunkModel trunk;
};

inline BuiltTrunk buildTrunk(const Points& pts, std::size_t trunk_points) {
  BuiltTrunk b;
  b.region.resize(trunk_points);
  std::iota(b.region.begin(), b.region.end(), 0);
  b.config = modeling::stageConfig(b.config);
  b.config.noise.sigma_m = 0.002;
  b.trunk = modeling::modelTrunk(pts, b.region, {{0, 0, 0}, {0, 0, 1.5}}, 0.03, b.config);
  return b;
}

}  // namespace test
}  // namespace dormant_tree_modeling
