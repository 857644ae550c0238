#include "dormant_tree_modeling/registration/coarse_search.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>
#include <unordered_set>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/parallel.h"
#include "dormant_tree_modeling/modeling/preprocess.h"

namespace dormant_tree_modeling {
namespace registration {

namespace {

constexpr double DEG = M_PI / 180.0;

std::int64_t cellOf(double v, double cell) {
  return static_cast<std::int64_t>(std::floor(v / cell));
}

// Three cell indices packed in one key (21 bits each: +-1e6 cells, 50 km at 5 cm).
std::uint64_t key3(std::int64_t x, std::int64_t y, std::int64_t z) {
  constexpr std::int64_t OFF = 1 << 20;
  return (static_cast<std::uint64_t>(x + OFF) << 42) | (static_cast<std::uint64_t>(y + OFF) << 21) |
         static_cast<std::uint64_t>(z + OFF);
}

// A dense top-down grid of the target: per column, a bit per height slab that holds points
// (64 slabs from the lowest point), dilated by one slab against noise and slab edges.
struct Columns {
  std::int64_t x0 = 0, y0 = 0, nx = 0, ny = 0;
  double z0 = 0, slab = 0;
  std::vector<std::uint64_t> bits;
  std::uint64_t at(std::int64_t x, std::int64_t y) const {
    x -= x0;
    y -= y0;
    return x >= 0 && y >= 0 && x < nx && y < ny ? bits[y * nx + x] : 0;
  }
  int slabOf(double z) const { return static_cast<int>(std::floor((z - z0) / slab)); }
};

std::uint64_t slabBit(int s) {
  return s >= 0 && s < 64 ? std::uint64_t{1} << s : 0;
}

Columns columns(const Points& pts, double cell, double slab) {
  Columns g;
  std::int64_t x1 = INT64_MIN, y1 = INT64_MIN;
  g.x0 = g.y0 = INT64_MAX;
  g.z0 = INFINITY;
  g.slab = slab;
  for (const auto& p : pts) {
    g.x0 = std::min(g.x0, cellOf(p.x(), cell));
    g.y0 = std::min(g.y0, cellOf(p.y(), cell));
    x1 = std::max(x1, cellOf(p.x(), cell));
    y1 = std::max(y1, cellOf(p.y(), cell));
    g.z0 = std::min(g.z0, p.z());
  }
  g.z0 -= 2 * slab;  // room for the dilation and sources reaching a little lower
  g.nx = x1 - g.x0 + 1;
  g.ny = y1 - g.y0 + 1;
  if (g.nx * g.ny > 50'000'000)
    throw Error(ErrorCode::INVALID_ARGUMENT,
                "coarse search: the target spans too large an area for its grid cell");
  g.bits.assign(static_cast<std::size_t>(g.nx * g.ny), 0);
  for (const auto& p : pts) {
    const int s = g.slabOf(p.z());
    g.bits[(cellOf(p.y(), cell) - g.y0) * g.nx + (cellOf(p.x(), cell) - g.x0)] |=
        slabBit(s - 1) | slabBit(s) | slabBit(s + 1);
  }
  return g;
}

struct Shift {
  double yaw = 0;
  Eigen::Vector3d translation = Eigen::Vector3d::Zero();
  double score = 0;
  // The best shift at least second_place_m from the best one (score 0: none).
  Eigen::Vector3d second_translation = Eigen::Vector3d::Zero();
  double second_score = 0;
};

Eigen::Isometry3d poseOf(double yaw, const Eigen::Vector3d& t) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  p.translation() = t;
  return p;
}

// The height profiles of the two clouds, in slabs of the target's grid: one slab per bit.
constexpr int PROFILE_SLABS = 64;
// Without a hint, the heights tried are the best few matches of the two profiles.
constexpr std::size_t UNHINTED_HEIGHTS = 3;
// Headings closer than this many steps to a better one are the same peak.
constexpr double DISTINCT_HEADING_STEPS = 2.5;
// Headings kept for the 3-D step, per candidate asked for.
constexpr int HEADINGS_PER_CANDIDATE = 3;
// The 3-D step tries the horizontal neighbours half a cell away.
constexpr double REFINE_XY_SHARE = 0.5;

// The target's cells dilated by one (noise, cell edges).
std::unordered_set<std::uint64_t> dilatedCells(const Points& target, double cell) {
  std::unordered_set<std::uint64_t> cells3;
  cells3.reserve(target.size() * 27);
  for (const auto& p : target) {
    const std::int64_t x = cellOf(p.x(), cell), y = cellOf(p.y(), cell), z = cellOf(p.z(), cell);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz)
          cells3.insert(key3(x + dx, y + dy, z + dz));
  }
  return cells3;
}

// Where a heading puts the source before any shift.
struct Placement {
  const std::optional<Eigen::Isometry3d>& hint;
  Eigen::Vector3d source_mean, target_mean;

  // With a hint, the hint's place of the source centroid whatever the heading; without one,
  // the centroids on each other.
  Eigen::Vector3d baseTranslation(double yaw) const {
    const Eigen::Vector3d at = hint ? Eigen::Vector3d(*hint * source_mean) : target_mean;
    return at - poseOf(yaw, Eigen::Vector3d::Zero()) * source_mean;
  }
};

// Around the hint's heading within yaw_window_deg, or a full turn without a hint.
std::vector<double> headingsToTry(const std::optional<Eigen::Isometry3d>& hint,
                                  const CoarseSearchConfig& c) {
  double yaw0 = 0, window = M_PI;
  if (hint) {
    yaw0 = std::atan2(hint->linear()(1, 0), hint->linear()(0, 0));
    window = c.yaw_window_deg * DEG;
  }
  const int steps = std::max(0, static_cast<int>(std::floor(window / (c.yaw_step_deg * DEG))));
  std::vector<double> yaws;
  for (int k = -steps; k <= steps; ++k) {
    if (!hint && k == steps && 2 * steps * c.yaw_step_deg >= 360.0 - 1e-9)
      continue;  // a full turn: -180 and +180 are one heading
    yaws.push_back(yaw0 + k * c.yaw_step_deg * DEG);
  }
  return yaws;
}

// Height shifts (in slabs) to try: none with a hint (its height is good to a slab; the 3-D
// step refines it); without one, the best matches of the two height profiles.
std::vector<int> heightShifts(const Points& source, const Points& target, const Columns& grid,
                              const Placement& placement, const CoarseSearchConfig& c) {
  if (placement.hint)
    return {0};
  const double base_z = placement.target_mean.z() - placement.source_mean.z();
  std::vector<double> src(PROFILE_SLABS, 0.0), tgt(PROFILE_SLABS, 0.0);
  for (const auto& p : source) {
    const int k = grid.slabOf(p.z() + base_z);
    if (k >= 0 && k < PROFILE_SLABS)
      src[k] += 1;
  }
  for (const auto& p : target) {
    const int k = grid.slabOf(p.z());
    if (k >= 0 && k < PROFILE_SLABS)
      tgt[k] += 1;
  }
  const int zmax = static_cast<int>(std::ceil(c.z_window_unhinted_m / grid.slab));
  std::vector<std::pair<double, int>> corr;
  for (int dz = -zmax; dz <= zmax; ++dz) {
    double sum = 0;
    for (int k = 0; k < PROFILE_SLABS; ++k) {
      if (k + dz >= 0 && k + dz < PROFILE_SLABS)
        sum += std::min(src[k], tgt[k + dz]);
    }
    corr.emplace_back(-sum, dz);
  }
  std::sort(corr.begin(), corr.end());
  std::vector<int> dzs;
  for (std::size_t i = 0; i < corr.size() && dzs.size() < UNHINTED_HEIGHTS; ++i)
    dzs.push_back(corr[i].second);
  return dzs;
}

// The source's columns at one pose: their cells and a bit per occupied slab of the target's
// grid.
struct SourceColumns {
  std::vector<std::pair<std::int64_t, std::int64_t>> cells;
  std::vector<std::uint64_t> bits;
  int occupied = 0;  // slab bits set
};

SourceColumns sourceColumns(const Points& source, const Columns& grid,
                            const Eigen::Isometry3d& pose, double cell) {
  SourceColumns out;
  std::unordered_map<std::uint64_t, std::size_t> slot;
  for (const auto& p : source) {
    const Eigen::Vector3d q = pose * p;
    const std::int64_t x = cellOf(q.x(), cell), y = cellOf(q.y(), cell);
    const auto [it, fresh] = slot.emplace(key3(x, y, 0), out.cells.size());
    if (fresh) {
      out.cells.emplace_back(x, y);
      out.bits.push_back(0);
    }
    const std::uint64_t b = slabBit(grid.slabOf(q.z()));
    if (!(out.bits[it->second] & b))
      ++out.occupied;
    out.bits[it->second] |= b;
  }
  return out;
}

// The horizontal shift (within xy_window, at each height shift) whose source columns hit the
// target's most; ties go to the smaller shift (nearer the hint).
Shift bestShift(const Points& source, const Columns& grid, double yaw, const Eigen::Vector3d& base,
                const std::vector<int>& dzs, const CoarseSearchConfig& c) {
  const Eigen::Isometry3d pose = poseOf(yaw, base);
  const SourceColumns cols = sourceColumns(source, grid, pose, c.cell_m);
  const int w = static_cast<int>(std::ceil(c.xy_window_m / c.cell_m));
  const int side = 2 * w + 1;
  // Per horizontal shift, its best height's score and shift.
  std::vector<Shift> at(static_cast<std::size_t>(side) * side);
  Shift s;
  s.yaw = yaw;
  for (const int dz : dzs) {
    std::vector<std::uint64_t> shifted(cols.bits.size());
    for (std::size_t i = 0; i < cols.bits.size(); ++i)
      shifted[i] = dz >= 0 ? cols.bits[i] << dz : cols.bits[i] >> -dz;
    for (int dy = -w; dy <= w; ++dy) {
      for (int dx = -w; dx <= w; ++dx) {
        int hits = 0;
        for (std::size_t i = 0; i < cols.cells.size(); ++i)
          hits += __builtin_popcountll(
              shifted[i] & grid.at(cols.cells[i].first + dx, cols.cells[i].second + dy));
        const double score = static_cast<double>(hits) / std::max(cols.occupied, 1);
        const Eigen::Vector3d t(dx * c.cell_m, dy * c.cell_m, dz * grid.slab);
        Shift& here = at[static_cast<std::size_t>(dy + w) * side + (dx + w)];
        if (score > here.score) {
          here.score = score;
          here.translation = t;
        }
        if (score > s.score ||
            (score == s.score &&
             dx * dx + dy * dy < s.translation.head<2>().squaredNorm() / (c.cell_m * c.cell_m))) {
          s.score = score;
          s.translation = t;
        }
      }
    }
  }
  for (const Shift& other : at) {
    const double apart = (other.translation - s.translation).head<2>().norm();
    if (apart >= c.second_place_m && other.score > s.second_score) {
      s.second_score = other.score;
      s.second_translation = other.translation + pose.translation();
    }
  }
  s.translation += pose.translation();
  return s;
}

// The best headings that are local maxima over the heading: a heading within
// DISTINCT_HEADING_STEPS of a better one is the same peak.
std::vector<Shift> distinctHeadings(const std::vector<Shift>& best, const CoarseSearchConfig& c) {
  std::vector<int> order(best.size());
  for (std::size_t k = 0; k < order.size(); ++k)
    order[k] = static_cast<int>(k);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return best[a].score > best[b].score; });
  std::vector<Shift> picked;
  for (const int k : order) {
    bool distinct = true;
    for (const auto& p : picked) {
      const double d = std::abs(std::remainder(p.yaw - best[k].yaw, 2 * M_PI));
      if (d < DISTINCT_HEADING_STEPS * c.yaw_step_deg * DEG)
        distinct = false;
    }
    if (distinct)
      picked.push_back(best[k]);
    if (static_cast<int>(picked.size()) >= HEADINGS_PER_CANDIDATE * c.candidates)
      break;
  }
  return picked;
}

// A heading's pose refined in 3-D: the height within z_window and half a cell around, scored
// by the share of source points in the target's dilated cells.
CoarseCandidate refineIn3d(const Points& source, const std::unordered_set<std::uint64_t>& cells3,
                           const Shift& shift, const CoarseSearchConfig& c) {
  const int zs = static_cast<int>(std::ceil(c.z_window_m / c.z_step_m));
  const Eigen::Isometry3d pose = poseOf(shift.yaw, shift.translation);
  Points moved;
  moved.reserve(source.size());
  for (const auto& p : source)
    moved.push_back(pose * p);
  CoarseCandidate best;
  for (int iz = -zs; iz <= zs; ++iz) {
    for (int dy = -1; dy <= 1; ++dy) {
      for (int dx = -1; dx <= 1; ++dx) {
        const Eigen::Vector3d d(dx * c.cell_m * REFINE_XY_SHARE, dy * c.cell_m * REFINE_XY_SHARE,
                                iz * c.z_step_m);
        int hits = 0;
        for (const auto& q : moved) {
          const Eigen::Vector3d r = q + d;
          hits += cells3.count(
              key3(cellOf(r.x(), c.cell_m), cellOf(r.y(), c.cell_m), cellOf(r.z(), c.cell_m)));
        }
        const double score = static_cast<double>(hits) / moved.size();
        if (score > best.score) {
          best.score = score;
          best.transform = poseOf(shift.yaw, shift.translation + d);
        }
      }
    }
  }
  return best;
}

// The best heading's second place, refined in 3-D, when its footprints overlap at all.
std::optional<CoarseCandidate> secondPlace(const std::vector<Shift>& picked, const Points& source,
                                           const std::unordered_set<std::uint64_t>& cells3,
                                           const CoarseSearchConfig& c) {
  if (picked.empty() || picked.front().second_score <= 0.0)
    return std::nullopt;
  Shift second = picked.front();
  second.translation = second.second_translation;
  second.score = second.second_score;
  return refineIn3d(source, cells3, second, c);
}

}  // namespace

std::vector<CoarseCandidate> coarseSearch(const Points& source_in, const Points& target_in,
                                          const std::optional<Eigen::Isometry3d>& hint,
                                          const CoarseSearchConfig& c) {
  c.validate();
  const Points source = modeling::voxelDownsample(source_in, c.cell_m);
  const Points target = modeling::voxelDownsample(target_in, c.cell_m);
  if (source.empty() || target.empty())
    throw Error(ErrorCode::EMPTY_INPUT, "coarse search: a cloud is empty");
  const Columns grid = columns(target, c.cell_m, 2 * c.cell_m);
  const std::unordered_set<std::uint64_t> cells3 = dilatedCells(target, c.cell_m);
  const Placement placement{hint, centroid(source), centroid(target)};
  const std::vector<double> yaws = headingsToTry(hint, c);
  const std::vector<int> dzs = heightShifts(source, target, grid, placement, c);

  // Top-down: the best horizontal shift per heading.
  std::vector<Shift> best(yaws.size());
  parallelFor(static_cast<int>(yaws.size()), [&](int k) {
    best[k] = bestShift(source, grid, yaws[k], placement.baseTranslation(yaws[k]), dzs, c);
  });
  // The best headings, then the height in 3-D.
  const std::vector<Shift> picked = distinctHeadings(best, c);
  std::vector<CoarseCandidate> out(picked.size());
  parallelFor(static_cast<int>(picked.size()),
              [&](int k) { out[k] = refineIn3d(source, cells3, picked[k], c); });
  std::sort(out.begin(), out.end(),
            [](const CoarseCandidate& a, const CoarseCandidate& b) { return a.score > b.score; });
  if (static_cast<int>(out.size()) > c.candidates)
    out.resize(c.candidates);
  if (const auto second = secondPlace(picked, source, cells3, c))
    out.push_back(*second);
  return out;
}

}  // namespace registration
}  // namespace dormant_tree_modeling
