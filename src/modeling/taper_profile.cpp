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
}  // namespace

std::optional<TaperProfile> TaperProfile::fit(const std::vector<Slice>& slices, double slice_height,
                                              double below, double above) {
  std::vector<std::pair<double, double>> pts;  // (arc length of the middle, corrected radius)
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
  std::vector<char> used(pts.size(), 1);
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
    std::vector<double> residuals(pts.size()), magnitude(pts.size());
    for (std::size_t k = 0; k < pts.size(); ++k) {
      residuals[k] = pts[k].second - p.at(pts[k].first);
      magnitude[k] = std::abs(residuals[k]);
    }
    const double spread = std::max(1.4826 * median(std::move(magnitude)), MIN_SPREAD);
    for (std::size_t k = 0; k < pts.size(); ++k)
      used[k] = residuals[k] > -below * spread && residuals[k] < above * spread;
  }
  return p;
}

double TaperProfile::at(double s) const {
  return c_.dot(basis(s));
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
