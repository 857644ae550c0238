#include "dormant_tree_modeling/modeling/branch_rays.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <unordered_map>

namespace dormant_tree_modeling {
namespace modeling {

namespace {

constexpr double DEG = M_PI / 180.0;
constexpr double HEIGHT_CELL = 0.02;        // m along the trunk axis
constexpr double AZIMUTH_CELL = 5.0 * DEG;  // 1.7 cm at 20 cm from the axis
constexpr double ELEVATION_STEP = 5.0 * DEG;
constexpr int AZIMUTH_CELLS = 72;
constexpr double MIN_OFF_AXIS = 1e-6;  // m

/// Cells keyed by one integer: height cell (offset to be non-negative), azimuth, elevation.
constexpr std::int64_t AZIMUTH_KEYS = 128, ELEVATION_KEYS = 64, HEIGHT_OFFSET = 1 << 20;

std::int64_t cellKey(std::int64_t height, int azimuth, int elevation) {
  return ((height + HEIGHT_OFFSET) * AZIMUTH_KEYS + azimuth) * ELEVATION_KEYS + elevation;
}

}  // namespace

std::optional<TrunkRay> strongestRay(const Points& pts, const Cylinder& trunk_segment,
                                     double min_elevation_deg, double max_elevation_deg) {
  const Eigen::Vector3d axis = trunk_segment.axis.normalized();
  const Eigen::Vector3d e1 = axis.unitOrthogonal(), e2 = axis.cross(e1);
  const int elevations = std::clamp(
      static_cast<int>(std::floor((max_elevation_deg - min_elevation_deg) * DEG / ELEVATION_STEP)) +
          1,
      1, static_cast<int>(ELEVATION_KEYS) - 2);
  std::vector<double> tangents(elevations);
  for (int k = 0; k < elevations; ++k)
    tangents[k] = std::tan(min_elevation_deg * DEG + k * ELEVATION_STEP);

  // Each point votes, per elevation, for the one cell of the ray that passes through it.
  std::unordered_map<std::int64_t, int> votes;
  votes.reserve(pts.size() * elevations);
  for (const auto& p : pts) {
    const Eigen::Vector3d v = p - trunk_segment.center;
    const double s = v.dot(axis);
    const double x = v.dot(e1), y = v.dot(e2);
    const double rho = std::hypot(x, y);
    if (rho < MIN_OFF_AXIS)
      continue;
    const double azimuth = std::atan2(y, x) + M_PI;  // 0 .. 2 pi
    const int a = std::min(AZIMUTH_CELLS - 1, static_cast<int>(azimuth / AZIMUTH_CELL));
    for (int k = 0; k < elevations; ++k) {
      const auto h = static_cast<std::int64_t>(std::floor((s - rho * tangents[k]) / HEIGHT_CELL));
      ++votes[cellKey(h, a, k)];
    }
  }
  if (votes.empty())
    return std::nullopt;

  // The peak of the votes summed over each cell and its 26 neighbours: a ray between cell
  // borders splits its votes.
  std::int64_t best_key = -1;
  int best = -1;
  for (const auto& [key, count] : votes) {
    (void)count;
    const int k = static_cast<int>(key % ELEVATION_KEYS);
    const int a = static_cast<int>((key / ELEVATION_KEYS) % AZIMUTH_KEYS);
    const std::int64_t h = key / (ELEVATION_KEYS * AZIMUTH_KEYS) - HEIGHT_OFFSET;
    int sum = 0;
    for (std::int64_t dh = -1; dh <= 1; ++dh) {
      for (int da = -1; da <= 1; ++da) {
        const int na = (a + da + AZIMUTH_CELLS) % AZIMUTH_CELLS;
        for (int dk = -1; dk <= 1; ++dk) {
          if (k + dk < 0 || k + dk >= elevations)
            continue;
          const auto it = votes.find(cellKey(h + dh, na, k + dk));
          if (it != votes.end())
            sum += it->second;
        }
      }
    }
    // Ties go to the smaller key: the answer must not depend on the map's order.
    if (sum > best || (sum == best && key < best_key)) {
      best = sum;
      best_key = key;
    }
  }
  const int k = static_cast<int>(best_key % ELEVATION_KEYS);
  const int a = static_cast<int>((best_key / ELEVATION_KEYS) % AZIMUTH_KEYS);
  const std::int64_t h = best_key / (ELEVATION_KEYS * AZIMUTH_KEYS) - HEIGHT_OFFSET;
  const double azimuth = (a + 0.5) * AZIMUTH_CELL - M_PI;
  const double elevation = min_elevation_deg * DEG + k * ELEVATION_STEP;
  TrunkRay ray;
  ray.origin = trunk_segment.center + (h + 0.5) * HEIGHT_CELL * axis;
  ray.direction = std::cos(elevation) * (std::cos(azimuth) * e1 + std::sin(azimuth) * e2) +
                  std::sin(elevation) * axis;
  ray.votes = best;
  return ray;
}

double rayDistance(const TrunkRay& ray, const Eigen::Vector3d& p) {
  const Eigen::Vector3d w = p - ray.origin;
  const double t = std::max(0.0, w.dot(ray.direction));
  return (w - t * ray.direction).norm();
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
