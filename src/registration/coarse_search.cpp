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
};

Eigen::Isometry3d poseOf(double yaw, const Eigen::Vector3d& t) {
  Eigen::Isometry3d p = Eigen::Isometry3d::Identity();
  p.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  p.translation() = t;
  return p;
}

}  // namespace

void CoarseSearchConfig::validate() const {
  auto require = [](bool ok, const char* m) {
    if (!ok)
      throw Error(ErrorCode::INVALID_ARGUMENT, std::string("coarse search: ") + m);
  };
  require(cell > 0, "cell must be > 0");
  require(yaw_window_deg >= 0 && yaw_window_deg <= 180, "yaw_window_deg must be in [0, 180]");
  require(yaw_step_deg > 0, "yaw_step_deg must be > 0");
  require(xy_window >= 0 && z_window >= 0 && z_window_unhinted >= 0, "windows must be >= 0");
  require(z_step > 0, "z_step must be > 0");
  require(candidates >= 1, "candidates must be >= 1");
}

std::vector<CoarseCandidate> coarseSearch(const Points& source_in, const Points& target_in,
                                          const std::optional<Eigen::Isometry3d>& hint,
                                          const CoarseSearchConfig& c) {
  c.validate();
  const Points source = modeling::voxelDownsample(source_in, c.cell);
  const Points target = modeling::voxelDownsample(target_in, c.cell);
  if (source.empty() || target.empty())
    throw Error(ErrorCode::EMPTY_INPUT, "coarse search: a cloud is empty");
  const Columns grid = columns(target, c.cell, 2 * c.cell);
  std::unordered_set<std::uint64_t> cells3;  // target cells dilated by one (noise, cell edges)
  cells3.reserve(target.size() * 27);
  for (const auto& p : target) {
    const std::int64_t x = cellOf(p.x(), c.cell), y = cellOf(p.y(), c.cell),
                       z = cellOf(p.z(), c.cell);
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz)
          cells3.insert(key3(x + dx, y + dy, z + dz));
  }

  // The headings to try, and the base translation of each.
  Eigen::Vector3d source_mean = Eigen::Vector3d::Zero(), target_mean = Eigen::Vector3d::Zero();
  for (const auto& p : source)
    source_mean += p;
  for (const auto& p : target)
    target_mean += p;
  source_mean /= static_cast<double>(source.size());
  target_mean /= static_cast<double>(target.size());
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
  auto baseTranslation = [&](double yaw) -> Eigen::Vector3d {
    if (hint) {
      // Keep the hint's translation for the source centroid, whatever the heading.
      const Eigen::Vector3d at = *hint * source_mean;
      return at - poseOf(yaw, Eigen::Vector3d::Zero()) * source_mean;
    }
    return target_mean - poseOf(yaw, Eigen::Vector3d::Zero()) * source_mean;
  };

  // Height shifts (in slabs) to try: none with a hint (its height is good to a slab; the 3-D
  // step below refines it); without one, the best matches of the two height profiles.
  std::vector<int> dzs = {0};
  if (!hint) {
    const double base_z = target_mean.z() - source_mean.z();
    std::vector<double> src(64, 0.0), tgt(64, 0.0);
    for (const auto& p : source) {
      const int k = grid.slabOf(p.z() + base_z);
      if (k >= 0 && k < 64)
        src[k] += 1;
    }
    for (const auto& p : target) {
      const int k = grid.slabOf(p.z());
      if (k >= 0 && k < 64)
        tgt[k] += 1;
    }
    const int zmax = static_cast<int>(std::ceil(c.z_window_unhinted / grid.slab));
    std::vector<std::pair<double, int>> corr;
    for (int dz = -zmax; dz <= zmax; ++dz) {
      double sum = 0;
      for (int k = 0; k < 64; ++k) {
        if (k + dz >= 0 && k + dz < 64)
          sum += std::min(src[k], tgt[k + dz]);
      }
      corr.emplace_back(-sum, dz);
    }
    std::sort(corr.begin(), corr.end());
    dzs.clear();
    for (std::size_t i = 0; i < corr.size() && dzs.size() < 3; ++i)
      dzs.push_back(corr[i].second);
  }

  // Top-down: best horizontal shift per heading.
  const int w = static_cast<int>(std::ceil(c.xy_window / c.cell));
  std::vector<Shift> best(yaws.size());
  parallelFor(static_cast<int>(yaws.size()), [&](int k) {
    const Eigen::Isometry3d pose = poseOf(yaws[k], baseTranslation(yaws[k]));
    // The source's columns: cell and slab bits (slabs of the target's grid).
    std::unordered_map<std::uint64_t, std::size_t> slot;
    std::vector<std::pair<std::int64_t, std::int64_t>> cells;
    std::vector<std::uint64_t> bits;
    int occupied = 0;
    for (const auto& p : source) {
      const Eigen::Vector3d q = pose * p;
      const std::int64_t x = cellOf(q.x(), c.cell), y = cellOf(q.y(), c.cell);
      const auto [it, fresh] = slot.emplace(key3(x, y, 0), cells.size());
      if (fresh) {
        cells.emplace_back(x, y);
        bits.push_back(0);
      }
      const std::uint64_t b = slabBit(grid.slabOf(q.z()));
      if (!(bits[it->second] & b))
        ++occupied;
      bits[it->second] |= b;
    }
    Shift s;
    s.yaw = yaws[k];
    for (const int dz : dzs) {
      std::vector<std::uint64_t> shifted(bits.size());
      for (std::size_t i = 0; i < bits.size(); ++i)
        shifted[i] = dz >= 0 ? bits[i] << dz : bits[i] >> -dz;
      for (int dy = -w; dy <= w; ++dy) {
        for (int dx = -w; dx <= w; ++dx) {
          int hits = 0;
          for (std::size_t i = 0; i < cells.size(); ++i)
            hits += __builtin_popcountll(shifted[i] &
                                         grid.at(cells[i].first + dx, cells[i].second + dy));
          // Ties go to the smaller shift (nearer the hint).
          const double score = static_cast<double>(hits) / std::max(occupied, 1);
          if (score > s.score ||
              (score == s.score &&
               dx * dx + dy * dy < s.translation.head<2>().squaredNorm() / (c.cell * c.cell))) {
            s.score = score;
            s.translation = Eigen::Vector3d(dx * c.cell, dy * c.cell, dz * grid.slab);
          }
        }
      }
    }
    s.translation += pose.translation();
    best[k] = s;
  });

  // The best headings (local maxima over the heading), then the height in 3-D.
  std::vector<int> order(yaws.size());
  for (std::size_t k = 0; k < order.size(); ++k)
    order[k] = static_cast<int>(k);
  std::sort(order.begin(), order.end(),
            [&](int a, int b) { return best[a].score > best[b].score; });
  std::vector<Shift> picked;
  for (const int k : order) {
    bool distinct = true;
    for (const auto& p : picked) {
      const double d = std::abs(std::remainder(p.yaw - best[k].yaw, 2 * M_PI));
      if (d < 2.5 * c.yaw_step_deg * DEG)
        distinct = false;
    }
    if (distinct)
      picked.push_back(best[k]);
    if (static_cast<int>(picked.size()) >= 3 * c.candidates)
      break;
  }
  const double zw = c.z_window;
  const int zs = static_cast<int>(std::ceil(zw / c.z_step));
  std::vector<CoarseCandidate> out(picked.size());
  parallelFor(static_cast<int>(picked.size()), [&](int k) {
    const Eigen::Isometry3d pose = poseOf(picked[k].yaw, picked[k].translation);
    Points moved;
    moved.reserve(source.size());
    for (const auto& p : source)
      moved.push_back(pose * p);
    CoarseCandidate bestc;
    for (int iz = -zs; iz <= zs; ++iz) {
      for (int dy = -1; dy <= 1; ++dy) {
        for (int dx = -1; dx <= 1; ++dx) {
          const Eigen::Vector3d d(dx * c.cell * 0.5, dy * c.cell * 0.5, iz * c.z_step);
          int hits = 0;
          for (const auto& q : moved) {
            const Eigen::Vector3d r = q + d;
            hits += cells3.count(
                key3(cellOf(r.x(), c.cell), cellOf(r.y(), c.cell), cellOf(r.z(), c.cell)));
          }
          const double score = static_cast<double>(hits) / moved.size();
          if (score > bestc.score) {
            bestc.score = score;
            bestc.transform = poseOf(picked[k].yaw, picked[k].translation + d);
          }
        }
      }
    }
    out[k] = bestc;
  });
  std::sort(out.begin(), out.end(),
            [](const CoarseCandidate& a, const CoarseCandidate& b) { return a.score > b.score; });
  if (static_cast<int>(out.size()) > c.candidates)
    out.resize(c.candidates);
  return out;
}

}  // namespace registration
}  // namespace dormant_tree_modeling
