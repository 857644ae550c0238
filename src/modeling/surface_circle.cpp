#include <Eigen/Dense>
#include <algorithm>
#include <cmath>

#include "dormant_tree_modeling/modeling/geometry_fit.h"

namespace dormant_tree_modeling {
namespace modeling {

namespace {

/// Global maximum of a Gaussian kernel density of `d` on [lo, hi]: a histogram at a quarter
/// of the bandwidth, smoothed, and the peak bin refined by a parabola through its neighbours.
double densityMode(const std::vector<double>& d, double lo, double hi, double bandwidth) {
  const double bin = 0.25 * bandwidth;
  const int reach = 12;  // bins each side of the kernel: 3 bandwidths
  const int bins = std::max(1, static_cast<int>(std::ceil((hi - lo) / bin))) + 1;
  std::vector<double> histogram(bins + 2 * reach, 0.0);
  for (const double v : d) {
    const int k = static_cast<int>(std::floor((v - lo) / bin + 0.5)) + reach;
    if (k >= 0 && k < static_cast<int>(histogram.size()))
      histogram[k] += 1.0;
  }
  std::vector<double> kernel(2 * reach + 1);
  for (int j = -reach; j <= reach; ++j)
    kernel[j + reach] = std::exp(-0.5 * (j * 0.25) * (j * 0.25));
  std::vector<double> density(bins, 0.0);
  for (int k = 0; k < bins; ++k) {
    for (int j = -reach; j <= reach; ++j)
      density[k] += kernel[j + reach] * histogram[k + reach + j];
  }
  const int peak =
      static_cast<int>(std::max_element(density.begin(), density.end()) - density.begin());
  double offset = 0.0;
  if (peak > 0 && peak + 1 < bins) {
    const double a = density[peak - 1], b = density[peak], c = density[peak + 1];
    const double den = a - 2.0 * b + c;
    if (den < 0.0)
      offset = std::clamp(0.5 * (a - c) / den, -0.5, 0.5);
  }
  return std::clamp(lo + (peak + offset) * bin, lo, hi);
}

}  // namespace

std::optional<Circle> surfaceCircle(const Points2& pts, const Circle& start, double sigma,
                                    double min_radius, double max_radius) {
  if (pts.size() < 3 || !(max_radius > min_radius) || !start.center.allFinite())
    return std::nullopt;
  const double bandwidth = std::max(0.6 * sigma, 0.001);
  Circle c = start;
  c.radius = std::clamp(c.radius, min_radius, max_radius);
  std::vector<double> d;
  for (int round = 0; round < 6; ++round) {
    d.clear();
    for (const auto& p : pts)
      d.push_back((p - c.center).norm());
    const double radius = densityMode(d, min_radius, max_radius, bandwidth);
    // Centre with the radius held: Gauss-Newton on sum (|p - c| - r)^2 over the points of the
    // surface peak; points further out (branches) or inside (noise) do not pull it.
    Eigen::Matrix2d JtJ = Eigen::Matrix2d::Zero();
    Eigen::Vector2d Jtr = Eigen::Vector2d::Zero();
    int used = 0;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const double e = d[i] - radius;
      if (std::abs(e) > 2.0 * bandwidth || d[i] < 1e-12)
        continue;
      const Eigen::Vector2d u = (pts[i] - c.center) / d[i];
      JtJ += u * u.transpose();
      Jtr += u * e;
      ++used;
    }
    const double moved_radius = std::abs(radius - c.radius);
    c.radius = radius;
    if (used < 3 || JtJ.determinant() < 1e-9 * used * used)
      break;
    const Eigen::Vector2d step = JtJ.ldlt().solve(Jtr);
    if (!step.allFinite())
      break;
    c.center += step;
    if (step.norm() < 1e-5 && moved_radius < 1e-5)
      break;
  }
  return c;
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
