#include "dormant_tree_modeling/calibration/rig_calibration.h"

#include <Eigen/Dense>
#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <map>
#include <unordered_map>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/statistics.h"
#include "dormant_tree_modeling/evaluation/matching.h"
#include "dormant_tree_modeling/io/pose_json.h"
#include "dormant_tree_modeling/io/tree_json.h"
#include "dormant_tree_modeling/modeling/noise_bias.h"
#include "dormant_tree_modeling/modeling/tree_model.h"
#include "dormant_tree_modeling/modeling/tree_modeler.h"
#include "dormant_tree_modeling/modeling/trunk_model.h"
#include "dormant_tree_modeling/registration/view_folder.h"

namespace dormant_tree_modeling {
namespace calibration {

namespace {

constexpr double SAME_DIAMETER_M = 1e-6;
constexpr double SAME_NOISE_M = 2e-4;  // scans whose noise estimates differ less share a row
constexpr double MAX_ROD_ANGLE_DEG = 30.0;
constexpr double MAX_ROD_ARC_M = 1.0;
// A footprint this large is a mismatch (a rod found on the wrong part, a wrong diameter).
constexpr double IMPLAUSIBLE_FOOTPRINT_M = 0.02;
// Silhouette samples are tried on 2 cm voxels of the points near the rods; a fit's outliers
// (a sample across two rods, at a rod's end) lie beyond 2.5 robust sigmas.
constexpr double SILHOUETTE_VOXEL_M = 0.02;
constexpr double SILHOUETTE_NEAR_ROD_M = 0.05;
constexpr double SILHOUETTE_OUTLIER_SIGMAS = 2.5;
constexpr double MIN_RANGE_SPREAD_M = 0.2;  // narrower: the growth is taken as constant
// Rods this alike (standard deviation of their diameters) cannot show how the width follows
// the diameter: the gain is taken as 1.
constexpr double MIN_DIAMETER_SPREAD_M = 0.002;
constexpr double MAX_DEPTH_SHARE = 1.5;
constexpr int DEPTH_SHARE_STEPS = 7;  // 1.5 / 2^7: about 1 % of the growth

struct Section {
  int index = 0;
  Eigen::Vector3d a, b;  // its axis, the margins taken off
  double radius = 0.0;
};

std::string mm(double m) {
  char b[32];
  std::snprintf(b, sizeof(b), "%.1f mm", 1000 * m);
  return b;
}

/// The pipe's constant-diameter sections long enough to measure, margins taken off.
std::vector<Section> pipeSections(const evaluation::Polyline& pipe, const RigSearch& search,
                                  double slice_height) {
  std::vector<Section> out;
  for (std::size_t k = 0; k + 1 < pipe.points.size() && k + 1 < pipe.diameters.size(); ++k) {
    const Eigen::Vector3d a = pipe.points[k], b = pipe.points[k + 1];
    const double len = (b - a).norm();
    if (std::abs(pipe.diameters[k] - pipe.diameters[k + 1]) > SAME_DIAMETER_M ||
        len < 2.0 * search.section_margin_m + search.min_slices * slice_height)
      continue;
    const Eigen::Vector3d d = (b - a) / len;
    out.push_back({static_cast<int>(k), a + search.section_margin_m * d,
                   b - search.section_margin_m * d, 0.5 * pipe.diameters[k]});
  }
  return out;
}

/// The modeler with raw radii: no footprint, no noise part, branch radii uncorrected.
modeling::ModelerConfig rawConfig(modeling::ModelerConfig c) {
  c.calibration = {};
  c.noise.correct_bias = true;
  c.branches.raw_radius = true;
  c.trunk_calibration = {};
  c.branch_calibration = {};
  return c;
}

/// The scan and its rig moved so that the pipe's foot is the origin: survey coordinates keep
/// their millimetres through the modeler's float stages.
void recentre(RigScan& scan) {
  if (scan.rig.trunk.points.empty())
    return;
  const Eigen::Vector3d origin = scan.rig.trunk.points.front();
  for (auto& p : scan.points)
    p -= origin;
  auto move = [&](evaluation::Polyline& line) {
    for (auto& p : line.points)
      p -= origin;
  };
  move(scan.rig.trunk);
  for (auto& b : scan.rig.primary_branches)
    move(b);
  for (auto& b : scan.rig.minor_branches)
    move(b);
  for (auto& v : scan.views)
    v.in_station = Eigen::Translation3d(-origin) * v.in_station;
}

/// Every rod the whole modeler finds near its stated axis, its raw radius, keyed on the scan's
/// standard noise reading `sigma`.
std::vector<RigSample> measureRods(const RigScan& scan, const modeling::ModelerConfig& raw,
                                   const RigSearch& search, double sigma,
                                   std::vector<std::string>* warnings) {
  modeling::ModelResult result;
  try {
    result = modeling::TreeModeler(raw).model(scan.points);
  } catch (const Error& e) {
    throw Error(e.code() == ErrorCode::EMPTY_INPUT ? ErrorCode::EMPTY_INPUT : ErrorCode::NO_TRUNK,
                "rig scan " + scan.name + ": " + e.what());
  }
  evaluation::MatchBounds bounds;
  bounds.min_distance = search.axis_tolerance_m;
  bounds.max_arc_length = MAX_ROD_ARC_M;
  bounds.max_angle_deg = MAX_ROD_ANGLE_DEG;
  const evaluation::TreeScore score = evaluation::evaluate(result.model, scan.rig, bounds);
  std::vector<RigSample> out;
  for (const auto& m : score.matches) {
    RigSample s;
    s.scan = scan.name;
    s.index = scan.rig.primary_branches[m.truth].id;
    s.radius = 0.5 * scan.rig.primary_branches[m.truth].diameters.front();
    s.apparent = 0.5 * m.detected_diameter;
    s.noise = sigma;
    out.push_back(s);
  }
  for (const int t : score.missed) {
    const auto& rod = scan.rig.primary_branches[t];
    warnings->push_back("rig scan " + scan.name + ": rod " + std::to_string(rod.id) + " (" +
                        mm(rod.diameters.front()) + " diameter) not found within " +
                        mm(search.axis_tolerance_m) + " of its axis in the rig file");
  }
  return out;
}

/// Every pipe section's raw radius (the median of the trunk step's slice circles along it) and
/// the noise the trunk step estimated on it, in `reading`.
std::vector<RigSample> measureSections(const RigScan& scan, const modeling::ModelerConfig& raw,
                                       const RigSearch& search, modeling::NoiseReading* reading,
                                       std::vector<std::string>* warnings) {
  std::vector<RigSample> out;
  for (const Section& sec : pipeSections(scan.rig.trunk, search, raw.trunk.slice_height_m)) {
    const Eigen::Vector3d d = (sec.b - sec.a).normalized();
    const double len = (sec.b - sec.a).norm(), reach = sec.radius + search.axis_tolerance_m;
    std::vector<int> region;
    for (std::size_t i = 0; i < scan.points.size(); ++i) {
      const Eigen::Vector3d w = scan.points[i] - sec.a;
      const double t = w.dot(d);
      if (t >= 0.0 && t <= len && (w - t * d).norm() <= reach)
        region.push_back(static_cast<int>(i));
    }
    std::vector<double> radii;
    double noise = 0.0;
    try {
      const auto trunk = modeling::modelTrunk(scan.points, region, {sec.a, sec.b}, sec.radius, raw);
      noise = trunk.noise_sigma;
      for (const auto& sl : trunk.slices) {
        const double t = (sl.center - sec.a).dot(d);
        if (sl.has_circle && t >= 0.0 && t <= len)
          radii.push_back(sl.radius);
      }
    } catch (const Error&) {
      // Reported below as not measured.
    }
    if (static_cast<int>(radii.size()) < search.min_slices) {
      warnings->push_back("rig scan " + scan.name + ": pipe section " + std::to_string(sec.index) +
                          " (" + mm(2 * sec.radius) +
                          " diameter) not measured: " + std::to_string(radii.size()) +
                          " slice circles within " + mm(search.axis_tolerance_m) + " of its axis");
      continue;
    }
    RigSample s;
    s.scan = scan.name;
    s.trunk = true;
    s.index = sec.index;
    s.radius = sec.radius;
    s.apparent = median(radii);
    out.push_back(s);
    if (noise > 0.0) {
      reading->radii_m.push_back(sec.radius);
      reading->noise_m.push_back(noise);
    }
  }
  return out;
}

/// The scan's reading at STANDARD_READING_RADIUS_M, which keys its rows; its sections' readings
/// sorted by radius (equal radii averaged).
double scanStandardReading(const RigScan& scan, modeling::NoiseReading* reading,
                           std::vector<std::string>* warnings) {
  std::map<double, std::pair<double, int>> by_radius;
  for (std::size_t i = 0; i < reading->radii_m.size(); ++i) {
    auto& e = by_radius[reading->radii_m[i]];
    e.first += reading->noise_m[i];
    ++e.second;
  }
  if (by_radius.empty()) {
    throw Error(ErrorCode::NO_TRUNK,
                "rig scan " + scan.name +
                    ": no pipe section measured, so the scanner's noise cannot be read on it: "
                    "check the rig file's pipe axis against the scan's frame");
  }
  *reading = {};
  for (const auto& [radius, e] : by_radius) {
    reading->radii_m.push_back(radius);
    reading->noise_m.push_back(e.first / e.second);
  }
  const double lo = reading->radii_m.front(), hi = reading->radii_m.back();
  const double r = modeling::STANDARD_READING_RADIUS_M;
  if (r < lo * (1.0 - modeling::COVERAGE_RADIUS_SLACK) ||
      r > hi * (1.0 + modeling::COVERAGE_RADIUS_SLACK)) {
    warnings->push_back("rig scan " + scan.name + ": its pipe sections measured (" + mm(2 * lo) +
                        " to " + mm(2 * hi) + " diameter) do not reach " + mm(2 * r) +
                        ", where the noise rows are read: the nearest section's reading is "
                        "taken; add a section of that diameter");
  }
  return reading->at(r);
}

/// Pool-adjacent-violators: the least-squares non-increasing sequence.
std::vector<double> nonIncreasing(const std::vector<double>& v, const std::vector<double>& w) {
  std::vector<double> value, weight;
  std::vector<int> size;
  for (std::size_t i = 0; i < v.size(); ++i) {
    value.push_back(v[i]);
    weight.push_back(w[i]);
    size.push_back(1);
    while (value.size() > 1 && value[value.size() - 2] < value.back()) {
      const std::size_t j = value.size() - 2;
      value[j] =
          (value[j] * weight[j] + value.back() * weight.back()) / (weight[j] + weight.back());
      weight[j] += weight.back();
      size[j] += size.back();
      value.pop_back();
      weight.pop_back();
      size.pop_back();
    }
  }
  std::vector<double> out;
  for (std::size_t j = 0; j < value.size(); ++j)
    out.insert(out.end(), size[j], value[j]);
  return out;
}

/// The noise rows: each scan's estimate, close ones merged.
std::vector<double> noiseRows(const std::vector<double>& sigmas) {
  std::vector<double> sorted = sigmas, rows;
  std::sort(sorted.begin(), sorted.end());
  std::vector<int> counts;
  for (const double s : sorted) {
    if (!rows.empty() && s - rows.back() < SAME_NOISE_M) {
      rows.back() = (rows.back() * counts.back() + s) / (counts.back() + 1);
      ++counts.back();
    } else {
      rows.push_back(s);
      counts.push_back(1);
    }
  }
  return rows;
}

std::size_t rowOf(const std::vector<double>& rows, double sigma) {
  std::size_t best = 0;
  for (std::size_t k = 1; k < rows.size(); ++k) {
    if (std::abs(rows[k] - sigma) < std::abs(rows[best] - sigma))
      best = k;
  }
  return best;
}

/// One row: the mean footprint per true radius, made non-increasing, then read at `radii`
/// (linear between, held beyond).
std::vector<double> footprintRow(const std::vector<const RigSample*>& samples,
                                 const std::vector<double>& radii) {
  std::map<double, std::pair<double, int>> by_radius;
  for (const RigSample* s : samples) {
    auto& e = by_radius[s->radius];
    e.first += s->footprint();
    ++e.second;
  }
  std::vector<double> r, v, w;
  for (const auto& [radius, e] : by_radius) {
    r.push_back(radius);
    v.push_back(e.first / e.second);
    w.push_back(e.second);
  }
  v = nonIncreasing(v, w);
  std::vector<double> out;
  for (const double x : radii) {
    if (x <= r.front()) {
      out.push_back(v.front());
    } else if (x >= r.back()) {
      out.push_back(v.back());
    } else {
      const std::size_t i = std::upper_bound(r.begin(), r.end(), x) - r.begin() - 1;
      const double t = (x - r[i]) / (r[i + 1] - r[i]);
      out.push_back((1.0 - t) * v[i] + t * v[i + 1]);
    }
  }
  return out;
}

/// The footprint table of one part (trunk sections or rods) over all scans.
modeling::RadiusCalibration footprintTable(const std::vector<RigSample>& samples, bool trunk,
                                           const std::vector<double>& rows) {
  modeling::RadiusCalibration t;
  std::vector<std::vector<const RigSample*>> per_row(rows.size());
  for (const auto& s : samples) {
    if (s.trunk != trunk)
      continue;
    t.radii.push_back(s.radius);
    per_row[rowOf(rows, s.noise)].push_back(&s);
  }
  std::sort(t.radii.begin(), t.radii.end());
  t.radii.erase(std::unique(t.radii.begin(), t.radii.end()), t.radii.end());
  for (std::size_t k = 0; k < rows.size(); ++k) {
    if (per_row[k].empty())
      continue;  // this scan showed none of this part: the other rows hold
    const auto row = footprintRow(per_row[k], t.radii);
    t.noise.push_back(rows[k]);
    t.bias.insert(t.bias.end(), row.begin(), row.end());
  }
  return t;
}

void checkCoverage(const std::vector<RigSample>& samples, bool trunk, const char* what,
                   std::vector<std::string>* warnings, double* lo, double* hi) {
  *lo = 1e300;
  *hi = 0.0;
  int implausible = 0;
  for (const auto& s : samples) {
    if (s.trunk != trunk)
      continue;
    *lo = std::min(*lo, s.radius);
    *hi = std::max(*hi, s.radius);
    implausible += std::abs(s.footprint()) > IMPLAUSIBLE_FOOTPRINT_M;
  }
  if (*hi <= 0.0) {
    throw Error(ErrorCode::NO_TRUNK, std::string("no ") + what +
                                         " of the rig was found in any scan: check the rig "
                                         "file's axes against the scan's frame");
  }
  if (*hi - *lo < SAME_DIAMETER_M) {
    warnings->push_back(std::string("the rig's ") + what + "s cover one diameter (" + mm(2 * *lo) +
                        "): the footprint is taken as constant over radius; add other diameters");
  }
  if (implausible > 0) {
    warnings->push_back(std::to_string(implausible) + " " + what +
                        " measurements differ from their true radius by more than " +
                        mm(IMPLAUSIBLE_FOOTPRINT_M) +
                        " beyond what noise explains: check the rig file's diameters");
  }
}

/// The rod whose axis a silhouette sample lies on, or -1.
int rodOf(const Eigen::Vector3d& p, const Eigen::Vector3d& dir, const evaluation::GroundTruth& rig,
          const RigSearch& search) {
  const double min_cos = std::cos(search.max_silhouette_angle_deg * M_PI / 180.0);
  for (std::size_t k = 0; k < rig.primary_branches.size(); ++k) {
    const evaluation::PolylinePoint q = evaluation::closestPoint(rig.primary_branches[k], p);
    if (q.distance < search.silhouette_reach_m && std::abs(q.direction.dot(dir)) >= min_cos)
      return static_cast<int>(k);
  }
  return -1;
}

bool nearARod(const Eigen::Vector3d& p, const evaluation::GroundTruth& rig) {
  for (const auto& rod : rig.primary_branches) {
    if (evaluation::closestPoint(rod, p).distance <
        0.5 * rod.diameters.front() + SILHOUETTE_NEAR_ROD_M)
      return true;
  }
  return false;
}

/// One station's (one side's) returns near the rods, in the rig's frame, and where axis
/// samples are tried (2 cm voxels of them).
struct StationPoints {
  modeling::Points pts, dirs, centres;
  std::vector<double> ranges;
  int rig = 0;  // index of its rig
};

std::vector<StationPoints> rigStations(const RigScan& scan, int rig_index) {
  std::map<int, std::vector<const registration::ViewInput*>> by_station;
  for (const auto& v : scan.views)
    by_station[v.station].push_back(&v);
  std::vector<StationPoints> out;
  for (const auto& [id, views] : by_station) {
    StationPoints s;
    s.rig = rig_index;
    std::unordered_map<long long, char> voxels;
    for (const auto* v : views) {
      const Eigen::Vector3d sensor = v->in_station * v->sensor;
      for (const auto& p : v->points) {
        const Eigen::Vector3d q = v->in_station * p;
        if (!q.allFinite() || !nearARod(q, scan.rig))
          continue;
        const Eigen::Vector3d d = sensor - q;
        s.pts.push_back(q);
        s.ranges.push_back(d.norm());
        s.dirs.push_back(d.normalized());
        const Eigen::Array3d cell = (q / SILHOUETTE_VOXEL_M).array().floor();
        const long long key = (static_cast<long long>(cell.x()) * 73856093LL) ^
                              (static_cast<long long>(cell.y()) * 19349663LL) ^
                              (static_cast<long long>(cell.z()) * 83492791LL);
        if (voxels.emplace(key, 1).second)
          s.centres.push_back(q);
      }
    }
    out.push_back(std::move(s));
  }
  return out;
}

/// Each axis sample on a rod, as the registration estimates it with `axes` (the width is
/// meaningful with no growth taken off).
std::vector<SilhouetteSample> samplesOnRods(const std::vector<StationPoints>& stations,
                                            const std::vector<evaluation::GroundTruth>& rigs,
                                            const RigSearch& search,
                                            const registration::AxisConfig& axes_config) {
  std::vector<SilhouetteSample> out;
  for (const auto& s : stations) {
    const evaluation::GroundTruth& rig = rigs[s.rig];
    const auto axes = registration::estimateAxes(s.pts, s.dirs, s.ranges, s.centres, axes_config);
    for (std::size_t i = 0; i < axes.size(); ++i) {
      const int k = rodOf(axes.points[i], axes.directions[i], rig, search);
      if (k < 0)
        continue;
      const auto& rod = rig.primary_branches[k];
      const Eigen::Vector3d dir = (rod.points.back() - rod.points.front()).normalized();
      const Eigen::Vector3d w = axes.points[i] - rod.points.front();
      const Eigen::Vector3d off = w - w.dot(dir) * dir;
      Eigen::Vector3d towards = axes.view_dirs[i] - axes.view_dirs[i].dot(dir) * dir;
      towards.normalize();
      out.push_back({axes.ranges[i], 2.0 * axes.radii[i], rod.diameters.front(), off.dot(towards)});
    }
  }
  return out;
}

/// The terms of the silhouette model width = gain x diameter + a + b range that the rods can
/// measure: the margin a always, b when their ranges vary, the gain when their diameters do
/// (else it is 1: the footprint only adds a margin, and the target is the width less it).
struct GrowthModel {
  bool per_range, per_diameter;

  Eigen::VectorXd terms(const SilhouetteSample& g) const {
    Eigen::VectorXd x(1 + per_range + per_diameter);
    x(0) = 1.0;
    if (per_range)
      x(1) = g.range;
    if (per_diameter)
      x(x.size() - 1) = g.diameter;
    return x;
  }
  double target(const SilhouetteSample& g) const {
    return per_diameter ? g.width : g.width - g.diameter;
  }
};

/// The standard deviation of one field over the samples.
double spread(const std::vector<SilhouetteSample>& samples, double SilhouetteSample::*field) {
  double n = 0, s = 0, ss = 0;
  for (const auto& g : samples) {
    n += 1;
    s += g.*field;
    ss += g.*field * g.*field;
  }
  return std::sqrt(std::max(ss / n - (s / n) * (s / n), 0.0));
}

/// Holds a gain the rods put outside [MIN_DIAMETER_GAIN, MAX_DIAMETER_GAIN] at the bound, with
/// a warning, and refits the margin for it so that widths stay unbiased at the rods' mean.
void holdGain(const std::vector<SilhouetteSample>& samples,
              modeling::SensorCalibration::Silhouette& s, std::vector<std::string>* warnings) {
  const double gain =
      std::clamp(s.diameter_gain, modeling::MIN_DIAMETER_GAIN, modeling::MAX_DIAMETER_GAIN);
  char text[160];
  std::snprintf(text, sizeof(text),
                "the silhouettes' width grows by %.2f of the rods' diameter, outside %s: taken "
                "as %.2f; the registration's branch radii will be poor",
                s.diameter_gain, modeling::diameterGainRange().c_str(), gain);
  warnings->push_back(text);
  double sum_d = 0, sum_w = 0, sum_r = 0;
  for (const auto& g : samples) {
    sum_d += g.diameter;
    sum_w += g.width;
    sum_r += g.range;
  }
  s.growth_m =
      (sum_w - gain * sum_d - s.growth_per_m * sum_r) / static_cast<double>(samples.size());
  s.diameter_gain = gain;
}

/// fitSilhouette on samples that are there.
modeling::SensorCalibration::Silhouette fitGrowth(const std::vector<SilhouetteSample>& samples,
                                                  std::vector<std::string>* warnings) {
  modeling::SensorCalibration::Silhouette s;
  s.measured = true;
  std::vector<double> r;
  for (const auto& g : samples)
    r.push_back(g.range);
  s.range_min_m = *std::min_element(r.begin(), r.end());
  s.range_max_m = *std::max_element(r.begin(), r.end());
  const GrowthModel model{spread(samples, &SilhouetteSample::range) > MIN_RANGE_SPREAD_M,
                          spread(samples, &SilhouetteSample::diameter) > MIN_DIAMETER_SPREAD_M};
  std::vector<char> keep(samples.size(), 1);
  Eigen::VectorXd p;
  for (int round = 0; round < 2; ++round) {
    const int k = 1 + model.per_range + model.per_diameter;
    Eigen::MatrixXd ata = Eigen::MatrixXd::Zero(k, k);
    Eigen::VectorXd atb = Eigen::VectorXd::Zero(k);
    for (std::size_t i = 0; i < samples.size(); ++i) {
      if (!keep[i])
        continue;
      const Eigen::VectorXd x = model.terms(samples[i]);
      ata += x * x.transpose();
      atb += x * model.target(samples[i]);
    }
    p = ata.ldlt().solve(atb);
    std::vector<double> residuals;
    for (const auto& g : samples)
      residuals.push_back(std::abs(model.target(g) - model.terms(g).dot(p)));
    const double sigma = sigmaFromAbsoluteDeviations(residuals);
    for (std::size_t i = 0; i < samples.size(); ++i)
      keep[i] = residuals[i] <= SILHOUETTE_OUTLIER_SIGMAS * sigma;
  }
  s.growth_m = p(0);
  s.growth_per_m = model.per_range ? p(1) : 0.0;
  s.diameter_gain = model.per_diameter ? p(p.size() - 1) : 1.0;
  if (!modeling::validDiameterGain(s.diameter_gain))
    holdGain(samples, s, warnings);
  return s;
}

/// The share of the silhouette growth the registration takes off so that its axes lie at the
/// rods' depth: the footprint's wings widen the silhouette but carry the near surface's range,
/// so the depth model wants less than the whole widening. Bisection on the median depth error,
/// which falls as the share grows (a smaller radius puts the axis nearer the surface).
double depthShare(const std::vector<StationPoints>& stations,
                  const std::vector<evaluation::GroundTruth>& rigs, const RigSearch& search,
                  const modeling::SensorCalibration::Silhouette& growth) {
  auto error = [&](double share) {
    // The axes as the registration will estimate them with this share.
    modeling::SensorCalibration trial;
    trial.silhouette = growth;
    trial.silhouette.depth_share = share;
    registration::RegistrationConfig c;
    registration::applySensorCalibration(trial, c);
    std::vector<double> e;
    for (const auto& s : samplesOnRods(stations, rigs, search, c.axes))
      e.push_back(s.depth_error);
    return e.empty() ? 0.0 : median(e);
  };
  double lo = 0.0, hi = MAX_DEPTH_SHARE;
  for (int it = 0; it < DEPTH_SHARE_STEPS; ++it) {
    const double mid = 0.5 * (lo + hi);
    (error(mid) > 0.0 ? hi : lo) = mid;
  }
  return 0.5 * (lo + hi);
}

}  // namespace

modeling::SensorCalibration::Silhouette fitSilhouette(const std::vector<SilhouetteSample>& samples,
                                                      std::vector<std::string>* warnings) {
  if (samples.empty())
    throw Error(ErrorCode::EMPTY_INPUT, "fitSilhouette: no silhouette samples");
  std::vector<std::string> unread;
  return fitGrowth(samples, warnings ? warnings : &unread);
}

RigScan readRigViews(const std::string& dir, const evaluation::GroundTruth& rig) {
  registration::ViewFolderConfig o;
  o.crop_radius = 0.0;
  o.use_guesses = false;
  o.ground_margin = -1.0;
  registration::ViewFolder folder = registration::readViewFolder(dir, o);
  std::map<std::string, Eigen::Isometry3d> registered;
  const std::string reg = dir + "/registration.json";
  if (std::filesystem::exists(reg)) {
    const auto doc = nlohmann::json::parse(io::readTextFile(reg), nullptr, false);
    if (doc.is_discarded() || !doc.contains("views") || !doc["views"].is_array())
      throw Error(ErrorCode::PARSE_ERROR, reg + ": no 'views' array");
    for (const auto& v : doc["views"]) {
      const auto pose = io::poseFromJson(v, "pose");
      if (pose && v.contains("name") && v["name"].is_string())
        registered[v["name"].get<std::string>()] = *pose;
    }
  }
  RigScan scan;
  scan.name = dir;
  scan.rig = rig;
  for (std::size_t i = 0; i < folder.views.size(); ++i) {
    registration::ViewInput v = folder.views[i];
    if (folder.true_poses[i]) {
      v.in_station = *folder.true_poses[i];
    } else if (registered.count(v.name)) {
      v.in_station = registered[v.name];
    } else {
      throw Error(ErrorCode::INVALID_ARGUMENT,
                  dir + ": view " + v.name +
                      " has no true_pose in views.json and no pose in registration.json: "
                      "register the rig's views (register_views) and copy registration.json "
                      "into the folder");
    }
    for (const auto& p : v.points) {
      if (p.allFinite())
        scan.points.push_back(v.in_station * p);
    }
    scan.views.push_back(std::move(v));
  }
  return scan;
}

RigCalibrationResult calibrateFromRig(const std::vector<RigScan>& scans,
                                      const modeling::ModelerConfig& config,
                                      const std::string& name, const RigSearch& search) {
  if (scans.empty())
    throw Error(ErrorCode::INVALID_ARGUMENT, "no rig scan given");
  const modeling::ModelerConfig raw = rawConfig(config);
  raw.validate();
  const auto trunk_noise = modeling::trunkNoiseBias(raw);
  const auto branch_noise = modeling::branchNoiseBias(raw);
  RigCalibrationResult result;
  std::vector<double> sigmas;
  std::vector<StationPoints> stations;
  std::vector<evaluation::GroundTruth> rigs;
  bool with_views = false;
  for (RigScan scan : scans) {
    if (scan.points.empty())
      throw Error(ErrorCode::EMPTY_INPUT, "rig scan " + scan.name + " has no points");
    if (pipeSections(scan.rig.trunk, search, raw.trunk.slice_height_m).empty() ||
        scan.rig.primary_branches.empty()) {
      throw Error(ErrorCode::INVALID_ARGUMENT,
                  "rig of " + scan.name +
                      ": needs a pipe ('trunk') with at least one constant-diameter section and "
                      "rods ('primary_branches')");
    }
    recentre(scan);
    modeling::NoiseReading reading;
    auto sections = measureSections(scan, raw, search, &reading, &result.warnings);
    const double sigma = scanStandardReading(scan, &reading, &result.warnings);
    auto rods = measureRods(scan, raw, search, sigma, &result.warnings);
    for (auto& s : rods)
      s.noise_part = branch_noise.biasAt(s.radius, sigma);
    for (auto& s : sections) {
      s.noise = sigma;
      s.noise_part = trunk_noise.biasAt(s.radius, sigma);
    }
    result.calibration.noise_readings.push_back(reading);
    result.samples.insert(result.samples.end(), sections.begin(), sections.end());
    result.samples.insert(result.samples.end(), rods.begin(), rods.end());
    sigmas.push_back(sigma);
    const auto sides = rigStations(scan, static_cast<int>(rigs.size()));
    stations.insert(stations.end(), sides.begin(), sides.end());
    rigs.push_back(scan.rig);
    with_views = with_views || !scan.views.empty();
    result.calibration.sources.push_back(scan.name);
  }
  modeling::SensorCalibration& c = result.calibration;
  c.name = name;
  checkCoverage(result.samples, true, "pipe section", &result.warnings,
                &c.coverage.trunk_radius_min_m, &c.coverage.trunk_radius_max_m);
  checkCoverage(result.samples, false, "rod", &result.warnings, &c.coverage.branch_radius_min_m,
                &c.coverage.branch_radius_max_m);
  const auto rows = noiseRows(sigmas);
  c.coverage.noise_min_m = rows.front();
  c.coverage.noise_max_m = rows.back();
  c.trunk_footprint = footprintTable(result.samples, true, rows);
  c.branch_footprint = footprintTable(result.samples, false, rows);
  const auto branch_table = modeling::addFootprint(branch_noise, c.branch_footprint);
  for (const double sigma : rows) {
    result.branch_floor_reach.push_back(
        {sigma, branch_table.floorAmbiguity(modeling::MIN_BRANCH_RADIUS_M, sigma).radius});
  }
  const auto silhouette = samplesOnRods(stations, rigs, search, registration::AxisConfig{});
  if (silhouette.size() >= static_cast<std::size_t>(search.min_silhouette_samples)) {
    c.silhouette = fitSilhouette(silhouette, &result.warnings);
    c.silhouette.depth_share = depthShare(stations, rigs, search, c.silhouette);
  } else {
    result.warnings.push_back(
        with_views ? "only " + std::to_string(silhouette.size()) +
                         " silhouette samples on the rods: the registration's silhouette growth "
                         "is not calibrated"
                   : "the rig was given as a cloud, not as views: the registration's silhouette "
                     "growth is not calibrated (give the rig's views folder as --scan)");
  }
  return result;
}

}  // namespace calibration
}  // namespace dormant_tree_modeling
