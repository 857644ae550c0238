#include "dormant_tree_modeling/modeling/preprocess.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <optional>
#include <string>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/parallel.h"
#include "dormant_tree_modeling/common/random.h"
#include "dormant_tree_modeling/common/statistics.h"
#include "dormant_tree_modeling/modeling/point_index.h"

namespace dormant_tree_modeling {
namespace modeling {

namespace {

constexpr double GROUND_BAND = 0.03;          // m above the ground plane removed with it
constexpr double GROUND_MIN_EXTENT = 0.8;     // m: a plane smaller than this is not the ground
constexpr std::size_t GROUND_SAMPLE = 50000;  // low points that score a ground hypothesis
constexpr double WIRE_BAND = 0.025;           // m around a wire line: its noisy returns
constexpr double WIRE_NEIGHBOURHOOD = 0.10;   // m, for the linearity test
constexpr double WIRE_LINEARITY = 0.1;        // second / first eigenvalue below this: a line
constexpr double WIRE_MAX_GAP = 0.35;         // m: a wire's returns are never sparser than this
constexpr double WIRE_MAX_TILT = 15.0 * M_PI / 180.0;
constexpr double WIRE_MAX_CROSSING = 10.0 * M_PI / 180.0;  // from the row's direction
constexpr int MAX_WIRES = 10;
constexpr double WIRE_TEST_VOXEL = 0.01;  // m

/// Removes points near a near-horizontal plane at the bottom of the cloud, if it is large.
std::size_t removeGround(Points& pts, std::uint64_t seed) {
  if (pts.size() < 100)
    return 0;
  double zmin = 1e300;
  for (const auto& p : pts)
    zmin = std::min(zmin, p.z());
  std::vector<int> low;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (pts[i].z() < zmin + 0.15)
      low.push_back(static_cast<int>(i));
  }
  if (low.size() < 50)
    return 0;
  // Hypotheses are scored on at most GROUND_SAMPLE of the low points (a whole terrestrial scan
  // has millions of ground returns; a tree's crop has a few thousand, all used).
  std::vector<int> sample;
  const std::size_t stride = (low.size() + GROUND_SAMPLE - 1) / GROUND_SAMPLE;
  for (std::size_t k = 0; k < low.size(); k += stride)
    sample.push_back(low[k]);
  Rng rng(seed);
  Eigen::Vector3d best_n = Eigen::Vector3d::UnitZ();
  double best_d = 0.0;
  std::size_t best_count = 0;
  for (int it = 0; it < 200; ++it) {
    const int last = static_cast<int>(sample.size()) - 1;
    const auto& a = pts[sample[rng.uniformInt(0, last)]];
    const auto& b = pts[sample[rng.uniformInt(0, last)]];
    const auto& c = pts[sample[rng.uniformInt(0, last)]];
    Eigen::Vector3d n = (b - a).cross(c - a);
    if (n.norm() < 1e-9)
      continue;
    n.normalize();
    if (n.z() < 0)
      n = -n;
    if (n.z() < std::cos(15.0 * M_PI / 180.0))
      continue;
    const double d = -n.dot(a);
    std::size_t count = 0;
    for (const int i : sample)
      count += std::abs(n.dot(pts[i]) + d) < 0.02;
    if (count > best_count) {
      best_count = count;
      best_n = n;
      best_d = d;
    }
  }
  // The plane must be wide in both horizontal directions: a trunk base is not the ground.
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (const int i : low) {
    if (std::abs(best_n.dot(pts[i]) + best_d) < 0.02) {
      lo = lo.cwiseMin(pts[i].head<2>());
      hi = hi.cwiseMax(pts[i].head<2>());
    }
  }
  if (best_count * stride < 100 || (hi - lo).minCoeff() < GROUND_MIN_EXTENT)
    return 0;
  const std::size_t before = pts.size();
  pts.erase(std::remove_if(
                pts.begin(), pts.end(),
                [&](const Eigen::Vector3d& p) { return best_n.dot(p) + best_d < GROUND_BAND; }),
            pts.end());
  return before - pts.size();
}

/// Grid cells keyed by one integer: per axis the offset from one cell below the cloud's lowest,
/// packed with x in the highest bits, so the keys sort as (x, y, z) do. Each axis has a spare
/// cell at both ends: a face neighbour's key is the key plus or minus that axis's unit.
struct CellKeys {
  std::vector<std::pair<std::uint64_t, int>> keyed;  ///< (key, point index), sorted
  std::array<std::uint64_t, 3> unit{};               ///< key step of one cell along x, y, z
  std::array<long, 3> lo{};                          ///< lowest occupied cell per axis
  std::array<long, 3> hi{};                          ///< highest occupied cell per axis
  double cell = 0.0;                                 ///< edge (m)
};

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

/// Every point's grid cell (edge `cell`) with its index, sorted by cell and then by index:
/// each cell's points form one run, in input order.
CellKeys sortedByCell(const Points& pts, double cell) {
  CellKeys out;
  out.keyed.resize(pts.size());
  if (pts.empty())
    return out;
  std::vector<std::array<long, 3>> cells(pts.size());
  std::array<long, 3> lo, hi;
  lo.fill(std::numeric_limits<long>::max());
  hi.fill(std::numeric_limits<long>::min());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    for (int a = 0; a < 3; ++a) {
      cells[i][a] = static_cast<long>(std::floor(pts[i](a) / cell));
      lo[a] = std::min(lo[a], cells[i][a]);
      hi[a] = std::max(hi[a], cells[i][a]);
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
  out.cell = cell;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    std::uint64_t key = 0;
    for (int a = 0; a < 3; ++a)
      key += static_cast<std::uint64_t>(cells[i][a] - lo[a] + 1) * out.unit[a];
    out.keyed[i] = {key, static_cast<int>(i)};
  }
  radixSortByKey(out.keyed, bits[0] + bits[1] + bits[2]);
  return out;
}

/// Calls fn(q) for every point q of pts within radius of p (radius at most grid.cell), from
/// the 3 x 3 x 3 cells around p's cell. p need not be one of pts.
template <typename Fn>
void forEachWithin(const CellKeys& grid, const Points& pts, const Eigen::Vector3d& p, double radius,
                   const Fn& fn) {
  std::array<long, 3> c;
  for (int a = 0; a < 3; ++a)
    c[a] = static_cast<long>(std::floor(p(a) / grid.cell));
  const double r2 = radius * radius;
  // Cells are numbered from one below the lowest occupied: keys exist for lo - 1 .. hi + 1.
  const auto key = [&](long x, long y, long z) {
    return static_cast<std::uint64_t>(x - grid.lo[0] + 1) * grid.unit[0] +
           static_cast<std::uint64_t>(y - grid.lo[1] + 1) * grid.unit[1] +
           static_cast<std::uint64_t>(z - grid.lo[2] + 1) * grid.unit[2];
  };
  const long z_lo = std::max(c[2] - 1, grid.lo[2]), z_hi = std::min(c[2] + 1, grid.hi[2]);
  if (z_lo > z_hi)
    return;
  for (long x = std::max(c[0] - 1, grid.lo[0]); x <= std::min(c[0] + 1, grid.hi[0]); ++x) {
    for (long y = std::max(c[1] - 1, grid.lo[1]); y <= std::min(c[1] + 1, grid.hi[1]); ++y) {
      // z is the key's lowest part: the three cells of a column are one run of keys.
      const std::uint64_t first = key(x, y, z_lo), last = key(x, y, z_hi);
      auto it = std::lower_bound(grid.keyed.begin(), grid.keyed.end(),
                                 std::make_pair(first, std::numeric_limits<int>::min()));
      for (; it != grid.keyed.end() && it->first <= last; ++it) {
        const Eigen::Vector3d& q = pts[it->second];
        if ((q - p).squaredNorm() <= r2)
          fn(q);
      }
    }
  }
}

/// Longest run of projections along a line without a gap above WIRE_MAX_GAP.
double longestRun(std::vector<double>& t) {
  if (t.empty())
    return 0.0;
  std::sort(t.begin(), t.end());
  double best = 0.0, start = t[0];
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (t[i] - t[i - 1] > WIRE_MAX_GAP)
      start = t[i];
    best = std::max(best, t[i] - start);
  }
  return best;
}

std::size_t removeWires(Points& pts, double min_length, std::uint64_t seed,
                        std::vector<Eigen::Vector3d>* directions) {
  if (pts.size() < 100)
    return 0;
  // Candidates: points whose 10 cm neighbourhood is a thin, near-horizontal line (a noisy wire
  // is a ribbon a few cm wide, still much narrower than long). Checked on a sample of points,
  // against a 1 cm grid of the cloud: the shape of a 10 cm ball needs no finer sampling. The
  // ball is gathered from the 27 cells of a 10 cm grid around the point (cheaper than a k-d
  // tree for 20000 balls of hundreds of points each; the same points).
  const Points coarse = voxelDownsample(pts, WIRE_TEST_VOXEL);
  const CellKeys grid = sortedByCell(coarse, WIRE_NEIGHBOURHOOD);
  const std::size_t stride = std::max<std::size_t>(1, pts.size() / 20000);
  const int samples = static_cast<int>((pts.size() + stride - 1) / stride);
  std::vector<char> linear(samples, 0);
  parallelFor(samples, [&](int k) {
    const Eigen::Vector3d& p = pts[static_cast<std::size_t>(k) * stride];
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
    int count = 0;
    forEachWithin(grid, coarse, p, WIRE_NEIGHBOURHOOD, [&](const Eigen::Vector3d& q) {
      const Eigen::Vector3d d = q - p;  // small offsets: the one-pass covariance stays exact
      sum += d;
      outer.noalias() += d * d.transpose();
      ++count;
    });
    if (count < 8)
      return;
    const Eigen::Vector3d mean = sum / count;
    const Eigen::Matrix3d cov = outer / count - mean * mean.transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
    const Eigen::Vector3d dir = es.eigenvectors().col(2);
    linear[k] = es.eigenvalues()(1) < WIRE_LINEARITY * es.eigenvalues()(2) &&
                std::abs(dir.z()) < std::sin(WIRE_MAX_TILT);
  });
  std::vector<int> candidates;
  for (int k = 0; k < samples; ++k) {
    if (linear[k])
      candidates.push_back(static_cast<int>(static_cast<std::size_t>(k) * stride));
  }
  Rng rng(seed);
  std::vector<std::pair<Eigen::Vector3d, std::vector<int>>> found;  // direction, points
  for (int wire = 0; wire < MAX_WIRES && candidates.size() >= 10; ++wire) {
    const int n = static_cast<int>(candidates.size());
    Eigen::Vector3d best_o = Eigen::Vector3d::Zero(), best_d = Eigen::Vector3d::UnitX();
    std::size_t best_count = 0;
    for (int it = 0; it < 300; ++it) {
      const Eigen::Vector3d& a = pts[candidates[rng.uniformInt(0, n - 1)]];
      const Eigen::Vector3d& b = pts[candidates[rng.uniformInt(0, n - 1)]];
      Eigen::Vector3d d = b - a;
      if (d.norm() < 0.3)
        continue;
      d.normalize();
      if (std::abs(d.z()) > std::sin(WIRE_MAX_TILT))
        continue;
      std::size_t count = 0;
      for (const int i : candidates) {
        const Eigen::Vector3d w = pts[i] - a;
        count += (w - w.dot(d) * d).squaredNorm() < WIRE_BAND * WIRE_BAND;
      }
      if (count > best_count) {
        best_count = count;
        best_o = a;
        best_d = d;
      }
    }
    if (best_count < 5)
      break;
    std::vector<double> along;
    std::vector<int> inliers;
    for (std::size_t i = 0; i < pts.size(); ++i) {
      const Eigen::Vector3d w = pts[i] - best_o;
      if ((w - w.dot(best_d) * best_d).squaredNorm() < WIRE_BAND * WIRE_BAND) {
        inliers.push_back(static_cast<int>(i));
        along.push_back(w.dot(best_d));
      }
    }
    // Whatever the verdict, these candidates are settled.
    std::vector<int> rest;
    for (const int i : candidates) {
      const Eigen::Vector3d w = pts[i] - best_o;
      if ((w - w.dot(best_d) * best_d).squaredNorm() >= WIRE_BAND * WIRE_BAND)
        rest.push_back(i);
    }
    candidates.swap(rest);
    if (longestRun(along) < min_length)
      continue;
    // Two sampled points fix the line to a few degrees; all its points to a fraction of one.
    Points line;
    for (const int i : inliers)
      line.push_back(pts[i]);
    found.push_back({principalAxis(line), std::move(inliers)});
  }
  // The wires of a row are parallel: the direction most of the lines found share is the row's,
  // and a "wire" across it is a pair of opposite branches in line (thick ones return more
  // points than a wire: the count alone does not tell).
  const auto parallel = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::abs(a.dot(b)) >= std::cos(WIRE_MAX_CROSSING);
  };
  std::size_t strongest = 0, best_votes = 0;
  for (std::size_t k = 0; k < found.size(); ++k) {
    std::size_t votes = 0;
    for (const auto& other : found)
      votes += parallel(found[k].first, other.first);
    if (votes > best_votes ||
        (votes == best_votes && found[k].second.size() > found[strongest].second.size())) {
      best_votes = votes;
      strongest = k;
    }
  }
  std::size_t removed = 0;
  std::vector<char> drop(pts.size(), 0);
  for (const auto& [dir, inliers] : found) {
    if (!parallel(dir, found[strongest].first))
      continue;
    directions->push_back(dir);
    for (const int i : inliers) {
      removed += !drop[i];
      drop[i] = 1;
    }
  }
  Points kept;
  kept.reserve(pts.size() - removed);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (!drop[i])
      kept.push_back(pts[i]);
  }
  pts.swap(kept);
  return removed;
}

}  // namespace

double medianSpacing(const Points& pts) {
  if (pts.size() < 2)
    return 0.0;
  return medianSpacing(pts, PointIndex(pts));
}

double medianSpacing(const Points& pts, const PointIndex& index) {
  if (pts.size() < 2)
    return 0.0;
  const std::size_t stride = std::max<std::size_t>(1, pts.size() / 2000);
  std::vector<double> d;
  for (std::size_t i = 0; i < pts.size(); i += stride) {
    const auto nn = index.nearest(pts[i], 2);
    if (nn.size() == 2)
      d.push_back((pts[nn[1]] - pts[i]).norm());
  }
  return median(std::move(d));
}

Points voxelDownsample(const Points& pts, double voxel) {
  if (voxel <= 0.0)
    return pts;
  // Sort the points by voxel (x, then y, then z), stably, and average each run: the same
  // cells, order and sums as a map of voxels, without a tree node per voxel.
  const auto keyed = sortedByCell(pts, voxel).keyed;
  Points out;
  for (std::size_t i = 0; i < keyed.size();) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    int count = 0;
    std::size_t j = i;
    for (; j < keyed.size() && keyed[j].first == keyed[i].first; ++j) {
      sum += pts[keyed[j].second];
      ++count;
    }
    out.push_back(sum / count);
    i = j;
  }
  return out;
}

std::vector<char> floatingMask(const Points& pts, double radius, int min_neighbors) {
  return floatingMask(pts, nullptr, radius, min_neighbors);
}

std::vector<char> floatingMask(const Points& pts, const PointIndex* index, double radius,
                               int min_neighbors) {
  std::vector<char> mask(pts.size(), 0);
  // Cells of edge h = 0.95 radius / sqrt(6): any point of a cell is within the radius of any
  // point of the same cell or of a face-adjacent one (at most h sqrt(6) apart). A cell whose
  // block of seven holds more than min_neighbors points settles all its points without a
  // search (most points of a dense scan); only the others go to the k-d tree. Same answer.
  const double cell = 0.95 * radius / std::sqrt(6.0);
  const CellKeys grid = sortedByCell(pts, cell);
  const auto& keyed = grid.keyed;
  std::vector<std::uint64_t> keys;
  std::vector<std::size_t> first;  // each cell's first entry in keyed; one past the end last
  for (std::size_t i = 0; i < keyed.size(); ++i) {
    if (i == 0 || keyed[i].first != keyed[i - 1].first) {
      keys.push_back(keyed[i].first);
      first.push_back(i);
    }
  }
  first.push_back(keyed.size());
  const std::size_t cells = keys.size();
  std::vector<int> block(cells);
  for (std::size_t c = 0; c < cells; ++c)
    block[c] = static_cast<int>(first[c + 1] - first[c]);
  // The keys are sorted, and so are the keys shifted by one face: each neighbour is found by
  // one pointer walking along with the cells (a merge), not by a search per cell.
  for (int axis = 0; axis < 3; ++axis) {
    for (const long step : {-1L, 1L}) {
      std::size_t p = 0;
      for (std::size_t c = 0; c < cells; ++c) {
        const std::uint64_t target =
            step > 0 ? keys[c] + grid.unit[axis] : keys[c] - grid.unit[axis];
        while (p < cells && keys[p] < target)
          ++p;
        if (p < cells && keys[p] == target)
          block[c] += static_cast<int>(first[p + 1] - first[p]);
      }
    }
  }
  std::vector<int> open;
  for (std::size_t c = 0; c < cells; ++c) {
    if (block[c] <= min_neighbors) {
      for (std::size_t k = first[c]; k < first[c + 1]; ++k)
        open.push_back(keyed[k].second);
    }
  }
  if (open.empty())
    return mask;
  std::optional<PointIndex> own;
  if (!index)
    index = &own.emplace(pts);
  parallelFor(static_cast<int>(open.size()), [&](int k) {
    const int i = open[k];
    mask[i] = index->countWithin(pts[i], radius, min_neighbors + 1) <= min_neighbors;
  });
  return mask;
}

Points preprocess(const Points& pts, const ModelerConfig& config, PreprocessStats* stats) {
  PreprocessStats s;
  s.input = pts.size();
  Points out = voxelDownsample(pts, config.voxel_size);
  s.after_voxel = out.size();
  if (config.ours_remove_clutter) {
    double radius = config.floating_radius;
    std::optional<PointIndex> index;
    if (config.ours_derive_parameters && out.size() >= 2) {
      // Sparse clouds (terrestrial scans of whole trees, a few cm between returns) would lose
      // everything to a fixed radius: scale it with the median nearest-neighbour spacing.
      radius = std::max(radius, 3.0 * medianSpacing(out, index.emplace(out)));
    }
    s.floating_radius = radius;
    const auto mask =
        floatingMask(out, index ? &*index : nullptr, radius, config.floating_min_neighbors);

    Points kept;
    for (std::size_t i = 0; i < out.size(); ++i) {
      if (!mask[i])
        kept.push_back(out[i]);
    }
    s.floating = out.size() - kept.size();
    out.swap(kept);
    s.ground = removeGround(out, config.seed + 11);
    s.wires = removeWires(out, config.wire_min_length, config.seed + 13, &s.wire_directions);
  }
  if (stats)
    *stats = s;
  return out;
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
