#include "dormant_tree_modeling/modeling/cluster_graph.h"
#include "dormant_tree_modeling/common/parallel.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <limits>
#include <memory>
#include <numeric>

#include "dormant_tree_modeling/modeling/point_index.h"

namespace dormant_tree_modeling {
namespace modeling {

namespace {

constexpr double DEG = M_PI / 180.0;
constexpr int MAX_CLUSTERS = 20000;
constexpr double LINK_MARGIN = 0.02;  // m: clusters whose boxes are farther apart never touch

Points gather(const Points& pts, const std::vector<int>& idx) {
  Points out;
  out.reserve(idx.size());
  for (const int i : idx)
    out.push_back(pts[i]);
  return out;
}

double angleToVertical(const Eigen::Vector3d& d) {
  return std::acos(std::clamp(d.normalized().z(), -1.0, 1.0));
}

}  // namespace

void updateCluster(const Points& pts, Cluster& c) {
  const Points sub = gather(pts, c.members);
  Eigen::Vector3d centroid;
  const Eigen::Vector3d axis = principalAxis(sub, &centroid);
  c.centroid = centroid;
  // A short piece of trunk has no clear principal direction: try the vertical as well and keep
  // the better least-squares fit.
  c.fit.reset();
  if (sub.size() >= 6) {
    for (const Eigen::Vector3d& guess :
         {Eigen::Vector3d(axis.z() < 0 ? -axis : axis), Eigen::Vector3d::UnitZ().eval()}) {
      const auto fit = fitCylinder(sub, guess);
      if (fit && (!c.fit || fit->mean_abs_error < c.fit->mean_abs_error))
        c.fit = fit;
    }
  }

  c.error = c.fit ? c.fit->mean_abs_error : std::numeric_limits<double>::infinity();
}

std::vector<Cluster> initialClusters(const Points& pts, const ModelerConfig& config,
                                     double spacing) {
  std::size_t per_cluster = static_cast<std::size_t>(config.graph.points_per_cluster);
  if (config.noise.derive_parameters && spacing > 0.0) {
    // N_c from density: a cluster about 15 cm across, whatever the scanner's point spacing
    // (the paper's 3000 points fit its density, not a sparse terrestrial scan).
    const double by_density = (0.15 / spacing) * (0.15 / spacing);
    per_cluster = static_cast<std::size_t>(
        std::clamp(by_density, 30.0, static_cast<double>(config.graph.points_per_cluster)));
  }
  const int k = std::max(1, static_cast<int>(pts.size() / per_cluster));
  const auto labels = kMeans(pts, k, config.graph.kmeans_iterations, config.seed);
  int count = 0;
  for (const int l : labels)
    count = std::max(count, l + 1);
  std::vector<Cluster> clusters(count);
  for (std::size_t i = 0; i < labels.size(); ++i)
    clusters[labels[i]].members.push_back(static_cast<int>(i));
  parallelFor(count, [&](int c) { updateCluster(pts, clusters[c]); });
  return clusters;
}

double derivedSplitError(const std::vector<Cluster>& clusters, double configured) {
  std::vector<double> errors;
  for (const auto& c : clusters) {
    if (std::isfinite(c.error))
      errors.push_back(c.error);
  }
  if (errors.empty())
    return configured;
  const std::size_t q = errors.size() / 4;
  std::nth_element(errors.begin(), errors.begin() + q, errors.end());
  // Capped: where every initial cluster spans junctions, the quartile says nothing of the noise.
  return std::clamp(1.5 * errors[q], configured, 5.0 * configured);
}

std::vector<Cluster> splitClusters(const Points& pts, std::vector<Cluster> clusters, double e_t,
                                   const ModelerConfig& config) {
  // Splits run in waves: every cluster of a wave is split on its own core, and each split's
  // k-means is seeded by the cluster itself (its first member and size), not by the order of
  // work, so the result is the same however many threads run.
  std::vector<Cluster> done;
  std::vector<Cluster> wave = std::move(clusters);
  while (!wave.empty()) {
    const int n = static_cast<int>(wave.size());
    std::vector<char> split(n, 0);
    int budget = MAX_CLUSTERS - static_cast<int>(done.size() + wave.size());
    for (int c = 0; c < n; ++c) {
      const bool small =
          static_cast<int>(wave[c].members.size()) < 2 * config.graph.min_cluster_points;
      if (wave[c].error > e_t && !small && budget > 0) {
        split[c] = 1;
        --budget;
      }
    }
    std::vector<std::array<Cluster, 2>> halves(n);
    parallelFor(n, [&](int c) {
      if (!split[c])
        return;
      const auto& members = wave[c].members;
      const std::uint64_t seed = config.seed + 101 +
                                 static_cast<std::uint64_t>(members.front()) * 1000003ULL +
                                 members.size();
      const auto labels = kMeans(gather(pts, members), 2, config.graph.kmeans_iterations, seed);
      for (std::size_t i = 0; i < labels.size(); ++i)
        halves[c][labels[i]].members.push_back(members[i]);
      if (halves[c][1].members.empty()) {
        split[c] = 0;
        return;
      }
      for (auto& h : halves[c])
        updateCluster(pts, h);
    });
    std::vector<Cluster> next;
    for (int c = 0; c < n; ++c) {
      if (!split[c]) {
        done.push_back(std::move(wave[c]));
        continue;
      }
      for (auto& h : halves[c])
        next.push_back(std::move(h));
    }
    wave.swap(next);
  }
  return done;
}

std::vector<Cluster> mergeClusters(const Points& pts, std::vector<Cluster> clusters, double d_t) {
  for (bool merged = true; merged;) {
    merged = false;
    const int n = static_cast<int>(clusters.size());
    std::vector<int> parent(n);
    std::iota(parent.begin(), parent.end(), 0);
    std::function<int(int)> find = [&](int i) {
      return parent[i] == i ? i : parent[i] = find(parent[i]);
    };
    for (int i = 0; i < n; ++i) {
      for (int k = i + 1; k < n; ++k) {
        if ((clusters[i].centroid - clusters[k].centroid).norm() < d_t && find(i) != find(k)) {
          parent[find(k)] = find(i);
          merged = true;
        }
      }
    }
    if (!merged)
      break;
    std::vector<Cluster> next;
    std::vector<int> slot(n, -1);
    for (int i = 0; i < n; ++i) {
      const int r = find(i);
      if (slot[r] < 0) {
        slot[r] = static_cast<int>(next.size());
        next.emplace_back();
      }
      auto& m = next[slot[r]].members;
      m.insert(m.end(), clusters[i].members.begin(), clusters[i].members.end());
    }
    parallelFor(static_cast<int>(next.size()), [&](int c) {
      std::sort(next[c].members.begin(), next[c].members.end());
      updateCluster(pts, next[c]);
    });
    clusters.swap(next);
  }
  return clusters;
}

std::vector<std::vector<int>> connectClusters(const Points& pts, const PointIndex& all,
                                              const std::vector<Cluster>& clusters,
                                              const ModelerConfig& config) {
  const int n = static_cast<int>(clusters.size());
  std::vector<int> owner(pts.size(), -1);
  std::vector<Eigen::Vector3d> lo(n), hi(n);
  std::vector<std::unique_ptr<PointIndex>> index(n);
  parallelFor(n, [&](int c) {
    lo[c] = Eigen::Vector3d::Constant(1e300);
    hi[c] = -lo[c];
    for (const int i : clusters[c].members) {
      owner[i] = c;  // members of different clusters are disjoint
      lo[c] = lo[c].cwiseMin(pts[i]);
      hi[c] = hi[c].cwiseMax(pts[i]);
    }
    index[c] = std::make_unique<PointIndex>(gather(pts, clusters[c].members));
  });
  // The point of `from` nearest to cluster `to`, and the share of its N neighbours in `to`.
  auto share = [&](int from, int to) {
    double best = std::numeric_limits<double>::infinity();
    int best_point = -1;
    for (const int i : clusters[from].members) {
      const Eigen::Vector3d& p = pts[i];
      if (((p.array() < lo[to].array() - LINK_MARGIN) || (p.array() > hi[to].array() + LINK_MARGIN))
              .any())
        continue;
      const auto nn = index[to]->nearest(p, 1);
      const double d = (pts[clusters[to].members[nn[0]]] - p).squaredNorm();
      if (d < best) {
        best = d;
        best_point = i;
      }
    }
    if (best_point < 0)
      return 0.0;
    const auto nn = all.nearest(pts[best_point], config.graph.neighbors);
    int inside = 0;
    for (const int j : nn)
      inside += owner[j] == to;
    return static_cast<double>(inside) / static_cast<double>(nn.size());
  };
  // Each pair's test is independent: rows on all cores, assembled in the sequential order.
  std::vector<std::vector<int>> linked(n);
  parallelFor(n, [&](int i) {
    for (int k = i + 1; k < n; ++k) {
      if (((lo[i].array() > hi[k].array() + LINK_MARGIN) ||
           (lo[k].array() > hi[i].array() + LINK_MARGIN))
              .any()) {
        continue;
      }
      const double a = share(i, k);
      if (a < config.graph.n_low || a > config.graph.n_high)
        continue;
      const double b = share(k, i);
      if (b < config.graph.n_low || b > config.graph.n_high)
        continue;
      linked[i].push_back(k);
    }
  });
  std::vector<std::vector<int>> adjacency(n);
  for (int i = 0; i < n; ++i) {
    for (const int k : linked[i]) {
      adjacency[i].push_back(k);
      adjacency[k].push_back(i);
    }
  }
  return adjacency;
}

bool isTrunkBase(const Cluster& cluster, double zmin, const ModelerConfig& config) {
  return cluster.centroid.z() <= zmin + TRUNK_BASE_BAND_M &&
         static_cast<int>(cluster.members.size()) >= 2 * config.graph.min_cluster_points &&
         cluster.fit &&
         std::abs(cluster.fit->axis.z()) >= std::cos(config.trunk.max_tilt_deg * DEG);
}

// Algorithm 2 as the paper writes it: one walk up the cluster graph from the trunk base.
TrunkPath findTrunkPath(const std::vector<Cluster>& clusters,
                        const std::vector<std::vector<int>>& adjacency,
                        const ModelerConfig& config) {
  const int n = static_cast<int>(clusters.size());
  if (n == 0)
    return TrunkPath{};
  const double psi_t = config.graph.psi_t_deg * DEG;
  auto radius = [&](int c) { return clusters[c].fit ? clusters[c].fit->radius : 0.0; };
  // Steps 5 and 6 from one start cluster.
  auto walk = [&](int start) {
    TrunkPath path;
    std::vector<char> in_trunk(n, 0);
    path.trunk.push_back(start);
    in_trunk[start] = 1;
    for (;;) {
      const int cur = path.trunk.back();
      // Reference radius: median of the last three trunk clusters with a fit.
      std::vector<double> recent;
      for (auto it = path.trunk.rbegin(); it != path.trunk.rend() && recent.size() < 3; ++it) {
        if (radius(*it) > 0.0)
          recent.push_back(radius(*it));
      }
      std::sort(recent.begin(), recent.end());
      const double r_ref = recent.empty() ? 0.0 : recent[recent.size() / 2];
      int next = -1;
      double best = std::numeric_limits<double>::infinity();
      for (const int k : adjacency[cur]) {
        if (in_trunk[k])
          continue;
        const double psi = angleToVertical(clusters[k].centroid - clusters[cur].centroid);
        if (psi >= psi_t)
          continue;
        double score = psi;
        if (config.graph.follow_diameter && r_ref > 0.0 && radius(k) > 0.0) {
          score = psi / psi_t + std::abs(std::log(radius(k) / r_ref));
        }
        if (score < best) {
          best = score;
          next = k;
        }
      }
      if (next < 0)
        break;
      path.trunk.push_back(next);
      in_trunk[next] = 1;
    }
    std::vector<char> seen(n, 0);
    for (const int t : path.trunk) {
      for (const int k : adjacency[t]) {
        if (!in_trunk[k] && !seen[k]) {
          seen[k] = 1;
          path.primary.push_back(k);
        }
      }
    }
    return path;
  };
  double zmin = std::numeric_limits<double>::infinity();
  int lowest = 0;
  for (int c = 0; c < n; ++c) {
    if (clusters[c].centroid.z() < zmin) {
      zmin = clusters[c].centroid.z();
      lowest = c;
    }
  }
  if (!config.graph.follow_diameter)
    return walk(lowest);
  // Ours: every sizeable, near-vertical cylinder piece near the bottom is a candidate base (a
  // post or a neighbour's low branch can be lower than the target's base); the one whose walk
  // gathers the most tree - trunk and attached clusters - is the target's trunk.
  TrunkPath best_path = walk(lowest);
  std::size_t best_size = best_path.trunk.size() + best_path.primary.size();
  for (int c = 0; c < n; ++c) {
    if (c == lowest || adjacency[c].empty() || !isTrunkBase(clusters[c], zmin, config))
      continue;
    TrunkPath path = walk(c);
    const std::size_t size = path.trunk.size() + path.primary.size();
    if (size > best_size) {
      best_size = size;
      best_path = std::move(path);
    }
  }
  return best_path;
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
