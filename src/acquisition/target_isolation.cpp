#include "dormant_tree_modeling/acquisition/target_isolation.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <numeric>
#include <unordered_map>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace acquisition {

namespace {

// Upright columns: the band in bins of this height, most of them (this share) filled.
constexpr double UPRIGHT_BIN = 0.1;  // m
constexpr double UPRIGHT_FILL = 0.7;

struct CellKey {
  std::int64_t x, y, z;
  bool operator==(const CellKey& o) const { return x == o.x && y == o.y && z == o.z; }
};
struct CellHash {
  std::size_t operator()(const CellKey& k) const {
    return static_cast<std::size_t>(k.x * 73856093) ^ static_cast<std::size_t>(k.y * 19349663) ^
           static_cast<std::size_t>(k.z * 83492791);
  }
};

int findRoot(std::vector<int>& parent, int i) {
  while (parent[i] != i) {
    parent[i] = parent[parent[i]];
    i = parent[i];
  }
  return i;
}

// Ground level: the most populated 2 cm height bin among the lowest metre of points, if it
// holds enough of the cloud.
bool groundLevel(const Cloud& cloud, const IsolationConfig& c, double& z) {
  float lowest = INFINITY;
  for (const auto& p : cloud)
    lowest = std::min(lowest, p.z);
  constexpr double BIN = 0.02;
  std::map<int, std::size_t> bins;
  for (const auto& p : cloud) {
    if (p.z < lowest + 1.0)
      ++bins[static_cast<int>((p.z - lowest) / BIN)];
  }
  const auto best = std::max_element(
      bins.begin(), bins.end(), [](const auto& a, const auto& b) { return a.second < b.second; });
  if (best == bins.end() || best->second < c.ground_min_fraction * cloud.size())
    return false;
  z = lowest + (best->first + 1) * BIN;  // the top of the ground bin
  return true;
}

// The ground seen in the view, or the plan's when none is seen near it.
void findGround(const Cloud& cloud, const IsolationConfig& c, std::optional<double> ground_hint,
                IsolationResult& out) {
  out.ground_found = groundLevel(cloud, c, out.ground_z);
  if (ground_hint && std::isfinite(*ground_hint) &&
      (!out.ground_found || std::abs(out.ground_z - *ground_hint) > c.ground_hint_tolerance)) {
    out.ground_found = out.ground_from_plan = true;
    out.ground_z = *ground_hint;
  }
}

// Columns of cell x cell, keyed by their two indices.
std::int64_t columnKey(double x, double y, double cell) {
  return (static_cast<std::int64_t>(std::floor(x / cell)) << 32) ^
         (static_cast<std::int64_t>(std::floor(y / cell)) & 0xffffffff);
}

Eigen::Vector2d columnCentre(std::int64_t k, double cell) {
  return {(static_cast<double>(k >> 32) + 0.5) * cell,
          (static_cast<double>(static_cast<std::int32_t>(k & 0xffffffff)) + 0.5) * cell};
}

// The trunk band above the ground (every point when there is no ground).
struct Band {
  bool ground_found;
  double base;  // the ground's height, -inf without one
  const IsolationConfig& c;

  bool contains(const Point& p) const {
    return !ground_found || (p.z >= base + c.trunk_band_low && p.z <= base + c.trunk_band_high);
  }
};

struct TrunkCandidate {
  double score;
  Eigen::Vector2d centre;
};

// Columns of the band ahead of the sensor, scored by their points smoothed over 3 x 3 cells
// and weighted by their distance from the hint; the best first, those far below the best left
// out (at most max_candidates).
std::vector<TrunkCandidate> trunkCandidates(const Cloud& cloud, const Band& band,
                                            const Eigen::Vector2d& sensor,
                                            const Eigen::Vector2d& forward,
                                            const Eigen::Vector2d& hint, const IsolationConfig& c) {
  std::unordered_map<std::int64_t, std::size_t> counts;
  for (const auto& p : cloud) {
    if (band.contains(p))
      ++counts[columnKey(p.x, p.y, c.cell)];
  }
  std::vector<TrunkCandidate> candidates;
  for (const auto& [k, n] : counts) {
    const Eigen::Vector2d centre = columnCentre(k, c.cell);
    const double ahead = (centre - sensor).dot(forward);
    if (ahead < c.min_distance || ahead > c.max_distance)
      continue;
    const double off = (centre - hint).norm();
    std::size_t sum = 0;
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        const auto it =
            counts.find(columnKey(centre.x() + dx * c.cell, centre.y() + dy * c.cell, c.cell));
        sum += it == counts.end() ? 0 : it->second;
      }
    }
    candidates.push_back({sum * std::exp(-0.5 * std::pow(off / c.hint_sigma_m, 2)), centre});
  }
  std::sort(candidates.begin(), candidates.end(),
            [](const TrunkCandidate& a, const TrunkCandidate& b) { return a.score > b.score; });
  if (candidates.empty() || candidates.front().score == 0.0)
    throw Error(ErrorCode::EMPTY_INPUT, "target isolation: no tree ahead of the sensor");
  const double best_band = candidates.front().score;
  candidates.erase(std::find_if(candidates.begin(), candidates.end(),
                                [&](const TrunkCandidate& a) {
                                  return a.score < c.candidate_ratio * best_band;
                                }),
                   candidates.end());
  if (candidates.size() > c.max_candidates)
    candidates.resize(c.max_candidates);
  return candidates;
}

// A trunk has branches around it; a post or a neighbour's trunk within the hint's reach has
// few (seen from high up, a thick post can hold more points of the band than the trunk): each
// candidate's score grows with the points in a ring around it at branch height.
Eigen::Vector2d chooseTrunk(const Cloud& cloud, const Band& band,
                            const std::vector<TrunkCandidate>& candidates,
                            const IsolationConfig& c) {
  std::vector<std::size_t> ring(candidates.size(), 0);
  if (band.ground_found && candidates.size() > 1) {
    for (const auto& p : cloud) {
      const double h = p.z - band.base;
      if (h < c.branch_ring_low || h > c.branch_ring_high)
        continue;
      for (std::size_t i = 0; i < candidates.size(); ++i) {
        const double r = (Eigen::Vector2d(p.x, p.y) - candidates[i].centre).norm();
        ring[i] += r > c.branch_ring_inner && r < c.branch_ring_outer;
      }
    }
  }
  double best_score = -1.0;
  Eigen::Vector2d trunk = Eigen::Vector2d::Zero();
  for (std::size_t i = 0; i < candidates.size(); ++i) {
    const double score = candidates[i].score * (1.0 + static_cast<double>(ring[i]));
    if (score > best_score) {
      best_score = score;
      trunk = candidates[i].centre;
    }
  }
  return trunk;
}

// Other upright objects near the trunk (trellis posts, a neighbour's trunk): columns whose
// points fill most of the band's height, away from the trunk. Branches cross the band; they
// do not fill it.
std::vector<Eigen::Vector2d> uprightColumns(const Cloud& cloud, const Band& band,
                                            const Eigen::Vector2d& trunk,
                                            const IsolationConfig& c) {
  const int bins =
      std::max(1, static_cast<int>((c.trunk_band_high - c.trunk_band_low) / UPRIGHT_BIN));
  std::unordered_map<std::int64_t, std::uint32_t> filled;
  for (const auto& p : cloud) {
    if (!band.contains(p))
      continue;
    const int b =
        std::min(bins - 1, static_cast<int>((p.z - band.base - c.trunk_band_low) / UPRIGHT_BIN));
    filled[columnKey(p.x, p.y, c.cell)] |= 1u << b;
  }
  std::vector<Eigen::Vector2d> others;
  for (const auto& [k, mask] : filled) {
    const Eigen::Vector2d centre = columnCentre(k, c.cell);
    if (__builtin_popcount(mask) >= UPRIGHT_FILL * bins &&
        (centre - trunk).norm() > c.trunk_clearance)
      others.push_back(centre);
  }
  return others;
}

// The cylinder around the trunk above the ground, without the other upright columns.
std::vector<Point> crop(const Cloud& cloud, const Band& band,
                        const std::vector<Eigen::Vector2d>& others, const IsolationConfig& c,
                        IsolationResult& out) {
  std::vector<Point> kept;
  for (const auto& p : cloud) {
    if (band.ground_found && p.z < band.base + c.ground_margin) {
      ++out.ground_removed;
      continue;
    }
    const Eigen::Vector2d xy(p.x, p.y);
    const double r = (xy - out.trunk).norm();
    bool other = false;
    for (const auto& o : others)
      other = other || (xy - o).norm() < c.other_column_radius;
    if (r > c.crop_radius_m || other || (band.ground_found && p.z > band.base + c.max_height_m)) {
      ++out.outside_removed;
      continue;
    }
    kept.push_back(p);
  }
  return kept;
}

// Keeps the points of components (26-connected occupied cells, by union-find) of at least
// min_component_points into out.cloud.
void dropSmallComponents(const std::vector<Point>& kept, const IsolationConfig& c,
                         IsolationResult& out) {
  std::unordered_map<CellKey, int, CellHash> cell_index;
  std::vector<int> point_cell(kept.size());
  for (std::size_t i = 0; i < kept.size(); ++i) {
    const CellKey k{static_cast<std::int64_t>(std::floor(kept[i].x / c.component_cell)),
                    static_cast<std::int64_t>(std::floor(kept[i].y / c.component_cell)),
                    static_cast<std::int64_t>(std::floor(kept[i].z / c.component_cell))};
    const auto [it, added] = cell_index.emplace(k, static_cast<int>(cell_index.size()));
    point_cell[i] = it->second;
  }
  std::vector<int> parent(cell_index.size());
  std::iota(parent.begin(), parent.end(), 0);
  for (const auto& [k, i] : cell_index) {
    for (int dx = -1; dx <= 1; ++dx) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dz = -1; dz <= 1; ++dz) {
          const auto it = cell_index.find({k.x + dx, k.y + dy, k.z + dz});
          if (it != cell_index.end())
            parent[findRoot(parent, i)] = findRoot(parent, it->second);
        }
      }
    }
  }
  std::vector<std::size_t> size(parent.size(), 0);
  for (std::size_t i = 0; i < kept.size(); ++i)
    ++size[findRoot(parent, point_cell[i])];
  for (std::size_t i = 0; i < kept.size(); ++i) {
    if (size[findRoot(parent, point_cell[i])] >= c.min_component_points)
      out.cloud->push_back(kept[i]);
    else
      ++out.small_component_points;
  }
}

}  // namespace

void IsolationConfig::validate() const {
  auto require = [](bool ok, const char* m) {
    if (!ok)
      throw Error(ErrorCode::INVALID_ARGUMENT, std::string("target isolation: ") + m);
  };
  require(ground_margin >= 0 && ground_min_fraction >= 0 && ground_min_fraction < 1 &&
              ground_hint_tolerance > 0,
          "ground_margin >= 0, 0 <= ground_min_fraction < 1, ground_hint_tolerance > 0");
  require(trunk_band_low < trunk_band_high, "trunk_band_low < trunk_band_high");
  require(cell > 0 && component_cell > 0, "cell sizes must be > 0");
  require(hint_sigma_m > 0, "hint_sigma must be > 0");
  require(candidate_ratio > 0 && candidate_ratio <= 1 && max_candidates >= 1,
          "0 < candidate_ratio <= 1 and max_candidates >= 1");
  require(branch_ring_inner >= 0 && branch_ring_outer > branch_ring_inner &&
              branch_ring_high > branch_ring_low,
          "branch_ring_inner < branch_ring_outer and branch_ring_low < branch_ring_high");
  require(min_distance >= 0 && max_distance > min_distance, "0 <= min_distance < max_distance");
  require(crop_radius_m > 0 && max_height_m > 0, "crop_radius and max_height must be > 0");
  require(trunk_clearance > 0 && other_column_radius > 0,
          "trunk_clearance and other_column_radius must be > 0");
}

IsolationResult isolateTarget(const Cloud& cloud, const Eigen::Vector3d& sensor,
                              const Eigen::Vector3d& forward_in, const Eigen::Vector2d& hint,
                              const IsolationConfig& c, std::optional<double> ground_hint) {
  c.validate();
  if (cloud.empty())
    throw Error(ErrorCode::EMPTY_INPUT, "target isolation: the view is empty");
  Eigen::Vector2d forward(forward_in.x(), forward_in.y());
  if (forward.norm() < 1e-9)
    throw Error(ErrorCode::INVALID_ARGUMENT, "target isolation: forward must be horizontal");
  forward.normalize();
  IsolationResult out;
  findGround(cloud, c, ground_hint, out);
  const Band band{out.ground_found, out.ground_found ? out.ground_z : -INFINITY, c};
  std::vector<TrunkCandidate> candidates =
      trunkCandidates(cloud, band, sensor.head<2>(), forward, hint, c);
  out.trunk = chooseTrunk(cloud, band, candidates, c);
  const std::vector<Eigen::Vector2d> others =
      out.ground_found ? uprightColumns(cloud, band, out.trunk, c) : std::vector<Eigen::Vector2d>{};
  const std::vector<Point> kept = crop(cloud, band, others, c, out);
  out.cloud = std::make_shared<Cloud>();
  dropSmallComponents(kept, c, out);
  return out;
}

}  // namespace acquisition
}  // namespace dormant_tree_modeling
