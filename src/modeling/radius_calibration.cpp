#include "dormant_tree_modeling/modeling/radius_calibration.h"

#include <algorithm>
#include <cmath>

namespace dormant_tree_modeling {
namespace modeling {

namespace {

constexpr double MAX_NOISE_EXTRAPOLATION = 1.0;

}  // namespace

bool strictlyAscending(const std::vector<double>& values) {
  for (std::size_t i = 1; i < values.size(); ++i) {
    if (!(values[i] > values[i - 1]))
      return false;
  }
  return true;
}

bool RadiusCalibration::valid() const {
  return !radii.empty() && !noise.empty() && bias.size() == radii.size() * noise.size() &&
         strictlyAscending(radii) && strictlyAscending(noise);
}

double RadiusCalibration::biasAt(double radius, double sigma) const {
  if (!valid())
    return 0.0;
  const std::size_t n = radii.size();
  auto row = [&](std::size_t k) {
    if (n == 1)
      return bias[k * n];
    const auto [i, t] = gridPosition(radii, radius);
    return (1.0 - t) * bias[k * n + i] + t * bias[k * n + i + 1];
  };
  if (noise.size() == 1)
    return row(0);
  auto [k, u] = gridPosition(noise, sigma);
  // Past the noisiest row the bias keeps growing with the noise: continue the last two rows'
  // line (up to MAX_NOISE_EXTRAPOLATION of their spacing) rather than hold the last row.
  if (sigma > noise.back()) {
    const double spacing = noise.back() - noise[noise.size() - 2];
    u = 1.0 + std::min(MAX_NOISE_EXTRAPOLATION, (sigma - noise.back()) / spacing);
  }
  return (1.0 - u) * row(k) + u * row(k + 1);
}

double RadiusCalibration::correct(double apparent, double sigma, double min_radius) const {
  if (!valid())
    return std::max(apparent, min_radius);
  // apparent(r) = r + bias(r) rises with r in any sensible table; bisection finds its root
  // even where the bias falls almost as fast as r grows (thin sections under heavy noise).
  auto excess = [&](double r) { return r + biasAt(r, sigma) - apparent; };
  double lo = min_radius, hi = std::max(apparent, min_radius) + 0.05;
  if (excess(lo) >= 0.0)
    return min_radius;
  if (excess(hi) <= 0.0)
    return std::max(apparent - biasAt(apparent, sigma), min_radius);
  for (int it = 0; it < 50; ++it) {
    const double mid = 0.5 * (lo + hi);
    (excess(mid) < 0.0 ? lo : hi) = mid;
  }
  return 0.5 * (lo + hi);
}

bool RadiusCalibration::resolves(double radius, double sigma, double floor_radius) const {
  if (!valid())
    return radius > floor_radius;
  return radius + biasAt(radius, sigma) > floorAmbiguity(floor_radius, sigma).apparent;
}

RadiusCalibration::FloorAmbiguity RadiusCalibration::floorAmbiguity(double floor_radius,
                                                                    double sigma) const {
  auto apparent = [&](double r) { return r + biasAt(r, sigma); };
  FloorAmbiguity out{floor_radius, apparent(floor_radius)};
  if (!valid())
    return out;
  // The apparent radius is linear between the table's radii and grows as r beyond them: walk
  // its pieces with the widest reading so far. A piece ending no wider is read before; a
  // piece that rises past it is read before up to where it crosses.
  double from = floor_radius, widest = out.apparent;
  for (const double to : radii) {
    if (to <= from)
      continue;
    const double a = apparent(from), b = apparent(to);
    if (b <= widest) {
      out = {to, widest};
    } else if (a < widest) {
      out = {from + (widest - a) / (b - a) * (to - from), widest};
      widest = b;
    } else {
      widest = b;
    }
    from = to;
  }
  const double last = apparent(from);
  if (last < widest)
    out = {from + (widest - last), widest};
  return out;
}

std::pair<std::size_t, double> gridPosition(const std::vector<double>& grid, double x) {
  if (grid.size() < 2 || x <= grid.front())
    return {0, 0.0};
  if (x >= grid.back())
    return {grid.size() - 2, 1.0};
  const std::size_t i =
      static_cast<std::size_t>(std::upper_bound(grid.begin(), grid.end(), x) - grid.begin()) - 1;
  return {i, (x - grid[i]) / (grid[i + 1] - grid[i])};
}

double mapAlong(const std::vector<double>& from, const std::vector<double>& to, double v) {
  if (v <= from.front())
    return v * to.front() / from.front();
  if (v >= from.back())
    return v * to.back() / from.back();
  const std::size_t k = std::upper_bound(from.begin(), from.end(), v) - from.begin();
  const double t = (v - from[k - 1]) / (from[k] - from[k - 1]);
  return to[k - 1] + t * (to[k] - to[k - 1]);
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
