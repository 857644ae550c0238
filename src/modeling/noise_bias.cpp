#include "dormant_tree_modeling/modeling/noise_bias.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <map>
#include <mutex>
#include <tuple>

#include "dormant_tree_modeling/common/parallel.h"
#include "dormant_tree_modeling/common/random.h"
#include "dormant_tree_modeling/common/statistics.h"
#include "dormant_tree_modeling/modeling/geometry_fit.h"
#include "dormant_tree_modeling/modeling/noise_band.h"
#include "dormant_tree_modeling/modeling/trunk_model.h"

namespace dormant_tree_modeling {
namespace modeling {

namespace {

// Grids of the noise part: apple trunks and leaders, primaries, and the noise of laser
// scanners from a survey instrument to a cheap 2-D lidar.
const std::vector<double> TRUNK_RADII_M{0.004, 0.006, 0.008, 0.011, 0.015, 0.02,
                                        0.03,  0.045, 0.07,  0.1,   0.15};
const std::vector<double> BRANCH_RADII_M{0.0025, 0.003,  0.004, 0.005, 0.0065, 0.008,
                                         0.01,   0.0125, 0.015, 0.02,  0.03,   0.04};
const std::vector<double> NOISE_M{0.0005, 0.001, 0.002, 0.003, 0.0045, 0.006,
                                  0.008,  0.010, 0.012, 0.015, 0.020,  0.025};

// The imagined scan: views evenly around the object with a random turn, returns evenly across
// its silhouette, as the view plan's stations around the tree give. Repeats average the
// estimator's own scatter out of the table.
constexpr int VIEWS = 8;
constexpr int SLICE_RETURNS_PER_VIEW = 60;
constexpr int ROD_RETURNS_PER_VIEW = 150;
constexpr int REPEATS = 8;
constexpr double ROD_LENGTH_M = 0.25;  // about branches.fit_length_m
const double ROD_ELEVATIONS_RAD[] = {0.0, 20.0 * M_PI / 180.0, 40.0 * M_PI / 180.0};
// The trunk step bounds a slice radius by the trunk's (SLICE_*_RADIUS_SHARE), the branch step a
// branch's by the trunk radius where it leaves: primaries are 0.3..0.6 of it.
constexpr double TRUNK_TO_BRANCH = 2.5;
constexpr double MIN_BRANCH_BOUND_M = 0.025;
// Slice radii the estimator's reading is modelled at are rounded to this (m).
constexpr double READING_RADIUS_STEP_M = 0.001;
constexpr double MIN_AXIS_STEP_M = 1e-5;
// Keys of the two tables in the cache.
constexpr int TRUNK_TABLE = 0;
constexpr int BRANCH_TABLE = 1;
constexpr std::uint64_t READING_SEED = 319993ULL;

/// A return on a cylinder of radius r about `axis` through the origin, seen along beam b
/// (unit, not parallel to the axis), `lateral` across the silhouette (-1..1) and `along` the
/// axis, displaced by `noise` along the beam.
Eigen::Vector3d rodReturn(const Eigen::Vector3d& axis, const Eigen::Vector3d& b, double r,
                          double lateral, double along, double noise) {
  const Eigen::Vector3d across = axis.cross(b).normalized();
  const Eigen::Vector3d facing = (b - b.dot(axis) * axis).normalized();
  const double u = lateral * r;
  return along * axis + u * across - std::sqrt(r * r - u * u) * facing + noise * b;
}

/// A cross-section of radius r about the origin seen from VIEWS views evenly around (a random
/// turn), its returns displaced by Gaussian noise `sigma` along their beams.
Points2 noisySlice(double r, double sigma, Rng& rng) {
  Points2 plane;
  const double turn = rng.uniform(0.0, 2.0 * M_PI);
  for (int v = 0; v < VIEWS; ++v) {
    const double az = turn + 2.0 * M_PI * v / VIEWS;
    const Eigen::Vector3d b(std::cos(az), std::sin(az), 0.0);
    for (int k = 0; k < SLICE_RETURNS_PER_VIEW; ++k) {
      const Eigen::Vector3d q = rodReturn(Eigen::Vector3d::UnitZ(), b, r, rng.uniform(-1.0, 1.0),
                                          0.0, sigma * rng.normal());
      plane.emplace_back(q.x(), q.y());
    }
  }
  return plane;
}

/// The trunk step's circle options for a section of radius r under noise sigma.
CircleRansacConfig sliceOptions(const ModelerConfig& config, double r, double sigma,
                                std::uint64_t seed) {
  CircleRansacConfig o;
  o.threshold = config.noise.derive_parameters
                    ? std::max(config.fit.circle_threshold_m, noiseBand(sigma))
                    : config.fit.circle_threshold_m;
  o.iterations = config.fit.ransac_iterations;
  o.min_radius = std::max(MIN_TRUNK_RADIUS, SLICE_MIN_RADIUS_SHARE * r);
  o.max_radius = SLICE_MAX_RADIUS_SHARE * r;
  o.seed = seed;
  return o;
}

double sliceBias(const ModelerConfig& config, double r, double sigma, std::uint64_t seed) {
  double sum = 0.0;
  int n = 0;
  for (int rep = 0; rep < REPEATS; ++rep) {
    Rng rng = Rng::derive(seed, rep);
    const Points2 plane = noisySlice(r, sigma, rng);
    const CircleRansacConfig o = sliceOptions(config, r, sigma, rng.next());
    const auto c = measureSliceCircle(plane, o, true, o.min_radius, o.max_radius);
    if (c && c->surface) {
      sum += c->circle.radius - r;
      ++n;
    }
  }
  return n > 0 ? sum / n : 0.0;
}

double rodBias(double r, double sigma, std::uint64_t seed) {
  double sum = 0.0;
  int n = 0;
  for (int rep = 0; rep < REPEATS; ++rep) {
    Rng rng = Rng::derive(seed, rep);
    const double e = ROD_ELEVATIONS_RAD[rep % 3];
    const Eigen::Vector3d axis(std::cos(e), 0.0, std::sin(e));
    Points pts;
    const double turn = rng.uniform(0.0, 2.0 * M_PI);
    for (int v = 0; v < VIEWS; ++v) {
      const double az = turn + 2.0 * M_PI * v / VIEWS;
      const Eigen::Vector3d b(std::cos(az), std::sin(az), 0.0);
      // A view sees the rod in proportion to its silhouette's width.
      const int returns = static_cast<int>(ROD_RETURNS_PER_VIEW * axis.cross(b).norm());
      if (returns < 1)
        continue;
      for (int k = 0; k < returns; ++k) {
        pts.push_back(rodReturn(axis, b, r, rng.uniform(-1.0, 1.0), rng.uniform(0.0, ROD_LENGTH_M),
                                sigma * rng.normal()));
      }
    }
    const auto c = fitThinCylinder(pts, axis, sigma, 0.0,
                                   std::max(MIN_BRANCH_BOUND_M, TRUNK_TO_BRANCH * r), rng.next());
    if (c) {
      sum += c->radius - r;
      ++n;
    }
  }
  return n > 0 ? sum / n : 0.0;
}

/// What the modeler's noise estimator (estimateNoiseSigma: the radial residuals of trunk slices,
/// pooled) reports for returns of range noise `sigma` on one slice of each of `slice_radii`. It
/// keeps the residuals within half a slice's radius, so on slices not much thicker than the
/// noise it reads low.
double estimatedNoise(const ModelerConfig& config, double sigma,
                      const std::vector<double>& slice_radii, std::uint64_t seed) {
  std::vector<double> estimates;
  for (int rep = 0; rep < REPEATS; ++rep) {
    Rng rng = Rng::derive(seed, rep);
    std::vector<double> residuals;
    for (const double r : slice_radii) {
      const Points2 plane = noisySlice(r, sigma, rng);
      const CircleRansacConfig o = sliceOptions(config, r, sigma, rng.next());
      const auto c = measureSliceCircle(plane, o, true, o.min_radius, o.max_radius);
      if (!c)
        continue;
      for (const auto& q : plane) {
        const double d = (q - c->circle.center).norm() - c->circle.radius;
        if (std::abs(d) < 0.5 * c->circle.radius)
          residuals.push_back(d);
      }
    }
    if (!residuals.empty())
      estimates.push_back(noiseFromRadialResiduals(std::move(residuals)));
  }
  return estimates.empty() ? sigma : median(std::move(estimates));
}

/// The noise axis: the estimator's reading of each of NOISE_M on slices of `slice_radii`, kept
/// ascending.
std::vector<double> estimatedNoiseAxis(const ModelerConfig& config,
                                       const std::vector<double>& slice_radii, std::uint64_t seed) {
  std::vector<double> axis(NOISE_M.size());
  parallelFor(static_cast<int>(NOISE_M.size()), [&](int k) {
    axis[k] = estimatedNoise(config, NOISE_M[k], slice_radii, Rng::derive(seed, 1000 + k).next());
  });
  for (std::size_t k = 1; k < axis.size(); ++k)
    axis[k] = std::max(axis[k], axis[k - 1] + MIN_AXIS_STEP_M);
  return axis;
}

/// The table of `bias(r, sigma, seed)` over the radii and NOISE_M, all cores, seeded by cell;
/// its noise axis is what the modeler's estimator reads for each noise.
template <typename Bias>
RadiusCalibration tabulate(const ModelerConfig& config, const std::vector<double>& radii,
                           std::uint64_t seed, Bias bias) {
  RadiusCalibration t;
  t.radii = radii;
  t.noise = estimatedNoiseAxis(config, {STANDARD_READING_RADIUS_M}, seed);
  t.bias.assign(radii.size() * NOISE_M.size(), 0.0);
  const int cells = static_cast<int>(t.bias.size());
  parallelFor(cells, [&](int i) {
    const std::size_t k = i / radii.size(), j = i % radii.size();
    t.bias[i] = bias(radii[j], NOISE_M[k], Rng::derive(seed, i).next());
  });
  return t;
}

/// Tables (and noise axes) computed before, by what they depend on.
template <typename Value, typename Key>
Value cached(const Key& key, const std::function<Value()>& make) {
  static std::mutex mutex;
  static std::map<Key, Value> values;
  std::lock_guard<std::mutex> lock(mutex);
  auto it = values.find(key);
  if (it == values.end())
    it = values.emplace(key, make()).first;
  return it->second;
}

/// The estimator's readings on slices of `slice_radii` (rounded to READING_RADIUS_STEP_M),
/// computed once per configuration and radii.
std::vector<double> readingAxis(const ModelerConfig& config,
                                const std::vector<double>& slice_radii) {
  std::vector<long> steps;
  std::vector<double> radii;
  for (const double r : slice_radii) {
    steps.push_back(std::max(1L, std::lround(r / READING_RADIUS_STEP_M)));
    radii.push_back(steps.back() * READING_RADIUS_STEP_M);
  }
  const auto key = std::make_tuple(config.fit.circle_threshold_m, config.fit.ransac_iterations,
                                   config.noise.derive_parameters, config.seed, steps);
  return cached<std::vector<double>>(
      key, [&] { return estimatedNoiseAxis(config, radii, config.seed * READING_SEED); });
}

}  // namespace

double standardNoiseReading(const ModelerConfig& config, double sigma,
                            const std::vector<double>& slice_radii) {
  if (!(sigma > 0.0) || slice_radii.empty())
    return sigma;
  if (config.calibration.given())
    return config.calibration.standardReading(sigma, slice_radii);
  return mapAlong(readingAxis(config, slice_radii),
                  readingAxis(config, {STANDARD_READING_RADIUS_M}), sigma);
}

RadiusCalibration trunkNoiseBias(const ModelerConfig& config) {
  const auto key =
      std::make_tuple(TRUNK_TABLE, config.fit.circle_threshold_m, config.fit.ransac_iterations,
                      config.noise.derive_parameters, config.seed);
  return cached<RadiusCalibration>(key, [&] {
    return tabulate(
        config, TRUNK_RADII_M, config.seed * 104729ULL,
        [&](double r, double s, std::uint64_t seed) { return sliceBias(config, r, s, seed); });
  });
}

RadiusCalibration branchNoiseBias(const ModelerConfig& config) {
  const auto key =
      std::make_tuple(BRANCH_TABLE, config.fit.circle_threshold_m, config.fit.ransac_iterations,
                      config.noise.derive_parameters, config.seed);
  return cached<RadiusCalibration>(
      key, [&] { return tabulate(config, BRANCH_RADII_M, config.seed * 130363ULL, rodBias); });
}

double footprintBiasAt(const RadiusCalibration& footprint, double radius, double sigma) {
  if (!footprint.valid())
    return 0.0;
  return footprint.biasAt(radius,
                          std::clamp(sigma, footprint.noise.front(), footprint.noise.back()));
}

RadiusCalibration addFootprint(const RadiusCalibration& noise_part,
                               const RadiusCalibration& footprint) {
  RadiusCalibration t = noise_part;
  if (!footprint.valid())
    return t;
  for (std::size_t k = 0; k < t.noise.size(); ++k) {
    for (std::size_t j = 0; j < t.radii.size(); ++j)
      t.bias[k * t.radii.size() + j] += footprintBiasAt(footprint, t.radii[j], t.noise[k]);
  }
  return t;
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
