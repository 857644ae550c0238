#include "cell_grid.h"

#include <string>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace modeling {
namespace detail {

namespace {

/// Sorts (key, index) pairs, listed in increasing index, by key and then index: a stable LSD
/// radix sort on the `bits` low bits of the key, 11 a pass (a comparison sort of millions of
/// cells took most of a whole scan's voxel grid).
void radixSortByKey(std::vector<std::pair<std::uint64_t, int>>& v, int bits) {
  constexpr int DIGIT = 11;
  constexpr std::uint64_t MASK = (1UL << DIGIT) - 1;
  std::vector<std::pair<std::uint64_t, int>> moved(v.size());
  std::vector<std::size_t> start(MASK + 2);
  for (int shift = 0; shift < bits; shift += DIGIT) {
    std::fill(start.begin(), start.end(), 0);
    for (const auto& e : v)
      ++start[((e.first >> shift) & MASK) + 1];
    for (std::size_t b = 1; b < start.size(); ++b)
      start[b] += start[b - 1];
    for (const auto& e : v)
      moved[start[(e.first >> shift) & MASK]++] = e;
    v.swap(moved);
  }
}

}  // namespace

CellKeys sortedByCell(const Points& pts, double cell) {
  CellKeys out;
  out.cell = cell;
  out.keyed.resize(pts.size());
  if (pts.empty())
    return out;
  // The cells are computed twice (bounds, then keys): cheaper than keeping three integers per
  // point of a whole scan in memory.
  const auto cellOf = [cell](double x) { return static_cast<long>(std::floor(x / cell)); };
  std::array<long, 3> lo, hi;
  lo.fill(std::numeric_limits<long>::max());
  hi.fill(std::numeric_limits<long>::min());
  for (const auto& p : pts) {
    for (int a = 0; a < 3; ++a) {
      const long c = cellOf(p(a));
      lo[a] = std::min(lo[a], c);
      hi[a] = std::max(hi[a], c);
    }
  }
  std::array<int, 3> bits;
  for (int a = 0; a < 3; ++a) {
    bits[a] = 1;
    while (bits[a] < 63 && (1UL << bits[a]) < static_cast<std::uint64_t>(hi[a] - lo[a] + 3))
      ++bits[a];
  }
  if (bits[0] + bits[1] + bits[2] > 64) {
    throw Error(ErrorCode::INVALID_ARGUMENT,
                "the cloud spans more grid cells of " + std::to_string(cell) +
                    " m than 64-bit keys hold; use a larger cell (voxel_size)");
  }
  out.unit = {1UL << (bits[1] + bits[2]), 1UL << bits[2], 1UL};
  out.lo = lo;
  out.hi = hi;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Eigen::Vector3d& p = pts[i];
    out.keyed[i] = {out.key(cellOf(p.x()), cellOf(p.y()), cellOf(p.z())), static_cast<int>(i)};
  }
  radixSortByKey(out.keyed, bits[0] + bits[1] + bits[2]);
  return out;
}

double nearestDistance(const CellKeys& grid, const Points& pts, std::size_t i) {
  const Eigen::Vector3d& p = pts[i];
  const long span =
      std::max({grid.hi[0] - grid.lo[0], grid.hi[1] - grid.lo[1], grid.hi[2] - grid.lo[2], 0L}) + 1;
  // A point outside the cube of k cells around p's cell is at least k cells away; the inner
  // cubes are walked again as the cube grows, which a dense cloud never needs.
  for (long k = 1;; ++k) {
    float best = std::numeric_limits<float>::infinity();
    int nearest = -1;
    forEachInCube(grid, p, k, [&](int j) {
      if (j != static_cast<int>(i)) {
        const float d = squaredDistanceF(p, pts[j]);
        if (d < best || (d == best && j < nearest)) {
          best = d;
          nearest = j;
        }
      }
      return true;
    });
    if (nearest >= 0) {
      const double d = (pts[nearest] - p).norm();
      if (d <= k * grid.cell - FLOAT_SLACK || k >= span)
        return d;
    } else if (k >= span) {
      return 0.0;
    }
  }
}

int countWithin(const CellKeys& grid, const Points& pts, const Eigen::Vector3d& p, double radius,
                int limit) {
  const float r2 = static_cast<float>(radius * radius);
  int count = 0;
  forEachInCube(grid, p, 1, [&](int j) {
    count += squaredDistanceF(p, pts[j]) < r2;
    return count < limit;
  });
  return count;
}

}  // namespace detail
}  // namespace modeling
}  // namespace dormant_tree_modeling
