#pragma once

// Private to the modeling area: a regular grid over a cloud whose cells are found by sorted
// 64-bit keys (no hash map, no tree), for the preprocessing steps that look at every point's
// neighbourhood: the voxel grid, floating pixels, the wire test, the point spacing.

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <utility>
#include <vector>

#include "dormant_tree_modeling/modeling/geometry_fit.h"

namespace dormant_tree_modeling {
namespace modeling {
namespace detail {

/// @brief Grid cells keyed by one integer: per axis the offset from one cell below the cloud's
/// lowest, packed with x in the highest bits, so the keys sort as (x, y, z) do. Each axis has a
/// spare cell at both ends: a face neighbour's key is the key plus or minus that axis's unit.
struct CellKeys {
  std::vector<std::pair<std::uint64_t, int>> keyed;  ///< (key, point index), sorted
  std::array<std::uint64_t, 3> unit{};               ///< key step of one cell along x, y, z
  std::array<long, 3> lo{};                          ///< lowest occupied cell per axis
  std::array<long, 3> hi{};                          ///< highest occupied cell per axis
  double cell = 0.0;                                 ///< edge (m)

  /// @brief Key of cell (x, y, z), each from lo - 1 to hi + 1 on its axis.
  std::uint64_t key(long x, long y, long z) const {
    return static_cast<std::uint64_t>(x - lo[0] + 1) * unit[0] +
           static_cast<std::uint64_t>(y - lo[1] + 1) * unit[1] +
           static_cast<std::uint64_t>(z - lo[2] + 1) * unit[2];
  }
};

/// @brief Every point's grid cell (edge `cell`, m) with its index, sorted by cell and then by
/// index: each cell's points form one run, in input order.
/// @throws Error INVALID_ARGUMENT when the cloud spans more cells than 64-bit keys hold
CellKeys sortedByCell(const Points& pts, double cell);

/// @brief Calls fn(j) for the index j of every point in the cells at most k cells from p's
/// cell along each axis (a cube of 2k + 1 cells a side), until fn returns false.
/// @return false when fn stopped the walk
template <typename Fn>
bool forEachInCube(const CellKeys& grid, const Eigen::Vector3d& p, long k, const Fn& fn) {
  if (grid.keyed.empty())
    return true;
  std::array<long, 3> c;
  for (int a = 0; a < 3; ++a)
    c[a] = static_cast<long>(std::floor(p(a) / grid.cell));
  const long z_lo = std::max(c[2] - k, grid.lo[2]), z_hi = std::min(c[2] + k, grid.hi[2]);
  if (z_lo > z_hi)
    return true;
  for (long x = std::max(c[0] - k, grid.lo[0]); x <= std::min(c[0] + k, grid.hi[0]); ++x) {
    for (long y = std::max(c[1] - k, grid.lo[1]); y <= std::min(c[1] + k, grid.hi[1]); ++y) {
      // z is the key's lowest part: a column of cells is one run of keys.
      const std::uint64_t first = grid.key(x, y, z_lo), last = grid.key(x, y, z_hi);
      auto it = std::lower_bound(grid.keyed.begin(), grid.keyed.end(),
                                 std::make_pair(first, std::numeric_limits<int>::min()));
      for (; it != grid.keyed.end() && it->first <= last; ++it) {
        if (!fn(it->second))
          return false;
      }
    }
  }
  return true;
}

/// @brief Squared distance as FLANN's single-precision k-d tree measures it (PointIndex): the
/// grid searches give the same neighbours as the index, to the last bit.
inline float squaredDistanceF(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  float result = 0.0f;
  for (int i = 0; i < 3; ++i) {
    const float diff = static_cast<float>(a(i)) - static_cast<float>(b(i));
    result += diff * diff;
  }
  return result;
}

/// @brief Distance from pts[i] to its nearest other point (0 for a lone point), the neighbour
/// chosen by single-precision distance like PointIndex::nearest; cubes of cells around it grow
/// until no cell left unsearched can hold a nearer point.
double nearestDistance(const CellKeys& grid, const Points& pts, std::size_t i);

/// @brief How many points of pts (p itself included when it is one) lie closer than radius to
/// p in single precision, counting stopped at limit; grid.cell must be at least the radius.
int countWithin(const CellKeys& grid, const Points& pts, const Eigen::Vector3d& p, double radius,
                int limit);

/// @brief Slack (m) over single-precision rounding of coordinates within 100 m of the origin
/// (the modeler recentres survey coordinates).
constexpr double FLOAT_SLACK = 1e-5;

/// @brief A grid cell edge that holds every neighbour within radius in the 3 x 3 x 3 cells
/// around a point, single-precision rounding included.
inline double cellForRadius(double radius) {
  return radius + FLOAT_SLACK;
}

}  // namespace detail
}  // namespace modeling
}  // namespace dormant_tree_modeling
