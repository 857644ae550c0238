#include "dormant_tree_modeling/modeling/taper_profile.h"

#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "dormant_tree_modeling/common/statistics.h"

namespace dormant_tree_modeling {
namespace modeling {

namespace {
constexpr int ROUNDS = 4;
constexpr double MIN_SPREAD = 1e-4;  // m: a floor on the robust sigma of exact fixtures
// Slices within this height of the lowest may be cut by the ground's mixed pixels: where the
// ground behind a trunk lies within the scanner's echo merging distance along the beam (0.45 m
// for the LMS111 model, at the 30-40 degree depression of the trunk's base seen from the
// platform), edge returns land between trunk and ground, inside the circle.
constexpr double GROUND_MIXING_HEIGHT = 0.3;  // m
// The slices above a base run that say what it should read (median), and by how many robust
// sigmas of the slice-to-slice scatter all of the run must read under them.
constexpr double BASE_REFERENCE_HEIGHT = 0.25;  // m
constexpr std::size_t MIN_REFERENCE_SLICES = 3;
constexpr double BASE_STEP_SIGMAS = 1.0;

using Samples = std::vector<std::pair<double, double>>;  // (arc length of the middle, radius)

/// Robust sigma of one slice's radius from the steps between neighbours: taper and branch
/// bases move few of them.
double stepSpread(const Samples& pts) {
  std::vector<double> steps;
  for (std::size_t k = 1; k < pts.size(); ++k)
    steps.push_back(std::abs(pts[k].second - pts[k - 1].second));
  return std::max(sigmaFromAbsoluteDeviations(std::move(steps)) / std::sqrt(2.0), MIN_SPREAD);
}

/// Robust sigma of the honest slices' scatter about the profile, the smaller of two readings
/// that wide slices inflate in different ways: over every slice from `base` on (when more
/// than half read wide, as among steep scaffolds, their residuals set it) and over those under
/// the profile (when wide slices pull the profile above all the honest ones, theirs set it).
double honestSpread(const std::vector<double>& residuals, std::size_t base) {
  std::vector<double> all, under;
  for (std::size_t k = base; k < residuals.size(); ++k) {
    all.push_back(std::abs(residuals[k]));
    if (residuals[k] < 0.0)
      under.push_back(-residuals[k]);
  }
  double spread = sigmaFromAbsoluteDeviations(std::move(all));
  if (!under.empty())
    spread = std::min(spread, sigmaFromAbsoluteDeviations(std::move(under)));
  return std::max(spread, MIN_SPREAD);
}

/// The number of lowest slices the ground's mixed pixels cut: the longest run within
/// GROUND_MIXING_HEIGHT of the lowest slice whose every slice reads under the median of the
/// slices just above the run. A trunk thins upwards, so no honest base slice does.
std::size_t groundMixedBase(const Samples& pts) {
  const double spread = stepSpread(pts);
  std::size_t base = 0;
  double run_max = 0.0;
  for (std::size_t m = 1; m < pts.size(); ++m) {
    if (pts[m - 1].first - pts.front().first >= GROUND_MIXING_HEIGHT)
      break;
    run_max = std::max(run_max, pts[m - 1].second);
    std::vector<double> reference;
    for (std::size_t j = m; j < pts.size() && pts[j].first < pts[m].first + BASE_REFERENCE_HEIGHT;
         ++j) {
      reference.push_back(pts[j].second);
    }
    if (reference.size() >= MIN_REFERENCE_SLICES &&
        run_max < median(std::move(reference)) - BASE_STEP_SIGMAS * spread) {
      base = m;
    }
  }
  return base;
}
}  // namespace

std::optional<TaperProfile> TaperProfile::fit(const std::vector<Slice>& slices, double slice_height,
                                              double below, double above) {
  Samples pts;  // corrected radii
  for (const auto& sl : slices) {
    if (sl.has_circle)
      pts.emplace_back(sl.s0 + 0.5 * slice_height, sl.corrected_radius);
  }
  if (pts.size() < MIN_SLICES)
    return std::nullopt;
  TaperProfile p;
  p.s0_ = pts.front().first;
  p.s1_ = pts.back().first;
  if (!(p.s1_ - p.s0_ > 1e-6))
    return std::nullopt;
  const std::size_t base = groundMixedBase(pts);
  if (pts.size() - base < MIN_SLICES)
    return std::nullopt;
  p.hold_ = pts[base].first;
  std::vector<char> used(pts.size(), 0);
  std::fill(used.begin() + base, used.end(), 1);
  for (int round = 0; round < ROUNDS; ++round) {
    Eigen::Matrix4d AtA = Eigen::Matrix4d::Zero();
    Eigen::Vector4d Atb = Eigen::Vector4d::Zero();
    std::size_t n = 0;
    for (std::size_t k = 0; k < pts.size(); ++k) {
      if (!used[k])
        continue;
      const Eigen::Vector4d row = p.basis(pts[k].first);
      AtA += row * row.transpose();
      Atb += row * pts[k].second;
      ++n;
    }
    if (n < MIN_SLICES)
      return std::nullopt;
    const Eigen::Vector4d c = AtA.ldlt().solve(Atb);
    if (!c.allFinite())
      return std::nullopt;
    p.c_ = c;
    std::vector<double> residuals(pts.size());
    for (std::size_t k = 0; k < pts.size(); ++k)
      residuals[k] = pts[k].second - p.at(pts[k].first);
    const double spread = honestSpread(residuals, base);
    for (std::size_t k = 0; k < pts.size(); ++k)
      used[k] = k >= base && residuals[k] > -below * spread && residuals[k] < above * spread;
  }
  return p;
}

double TaperProfile::at(double s) const {
  return c_.dot(basis(std::max(s, hold_)));
}

double TaperProfile::mean(double a, double b) const {
  constexpr int SAMPLES = 16;
  double sum = 0.0;
  for (int i = 0; i < SAMPLES; ++i)
    sum += at(a + (b - a) * (i + 0.5) / SAMPLES);
  return sum / SAMPLES;
}

Eigen::Vector4d TaperProfile::basis(double s) const {
  const double t = std::clamp((s - s0_) / (s1_ - s0_), 0.0, 1.0);
  return Eigen::Vector4d(1.0, std::sqrt(t), t, t * t);
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
