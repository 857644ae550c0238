#include <algorithm>
#include <cmath>
#include <limits>

#include "dormant_tree_modeling/common/parallel.h"
#include "dormant_tree_modeling/common/random.h"
#include "dormant_tree_modeling/modeling/geometry_fit.h"

namespace dormant_tree_modeling {
namespace modeling {

namespace {
constexpr int BLOCK = 4096;        // points per task of the parallel loops
constexpr double ROUNDING = 1e-9;  // m of slack on triangle-inequality bounds
}  // namespace

std::vector<int> kMeans(const Points& pts, int k, int max_iterations, std::uint64_t seed) {
  const int n = static_cast<int>(pts.size());
  std::vector<int> labels(n, 0);
  k = std::clamp(k, 1, std::max(1, n));
  if (n == 0 || k == 1)
    return labels;
  Rng rng(seed);
  // k-means++ seeding: each next centre drawn with probability proportional to D^2. Each
  // point's nearest and second-nearest centre are kept as the centres arrive: that is the
  // first assignment of Lloyd's iterations, exactly, without scanning all k centres again.
  std::vector<Eigen::Vector3d> centres{pts[rng.uniformInt(0, n - 1)]};
  std::vector<double> d2(n, std::numeric_limits<double>::infinity());
  std::vector<double> second_d2(n, std::numeric_limits<double>::infinity());
  // Points go to the threads in blocks: a call per point would cost as much as its work.
  const int blocks = (n + BLOCK - 1) / BLOCK;
  const auto forEachPoint = [&](const auto& fn) {
    parallelFor(blocks, [&](int b) {
      const int end = std::min(n, (b + 1) * BLOCK);
      for (int i = b * BLOCK; i < end; ++i)
        fn(i);
    });
  };
  // Each block's sum of D^2 is kept with the block: the draw walks the blocks, then the points
  // of one block, instead of all points twice per centre on one core. The points come sorted by
  // voxel, so a block is a slab of the cloud: a block whose bounding box is farther from a new
  // centre than all its points' second-nearest centres cannot change and is skipped.
  std::vector<double> block_sum(blocks, 0.0);
  std::vector<double> block_reach(blocks, std::numeric_limits<double>::infinity());
  std::vector<Eigen::Vector3d> block_lo(blocks), block_hi(blocks);
  parallelFor(blocks, [&](int b) {
    const int end = std::min(n, (b + 1) * BLOCK);
    block_lo[b] = block_hi[b] = pts[b * BLOCK];
    for (int i = b * BLOCK; i < end; ++i) {
      block_lo[b] = block_lo[b].cwiseMin(pts[i]);
      block_hi[b] = block_hi[b].cwiseMax(pts[i]);
    }
  });
  auto admit = [&](int c) {
    // Same order and strict comparisons as a scan over the centres in index order.
    const Eigen::Vector3d centre = centres[c];
    parallelFor(blocks, [&](int b) {
      const Eigen::Vector3d outside =
          (block_lo[b] - centre).cwiseMax(centre - block_hi[b]).cwiseMax(0.0);
      if (outside.squaredNorm() >= block_reach[b])
        return;
      const int end = std::min(n, (b + 1) * BLOCK);
      double sum = 0.0, reach = 0.0;
      for (int i = b * BLOCK; i < end; ++i) {
        const double d = (pts[i] - centre).squaredNorm();
        if (d < d2[i]) {
          second_d2[i] = d2[i];
          d2[i] = d;
          labels[i] = c;
        } else if (d < second_d2[i]) {
          second_d2[i] = d;
        }
        sum += d2[i];
        reach = std::max(reach, second_d2[i]);
      }
      block_sum[b] = sum;
      block_reach[b] = reach;
    });
  };
  admit(0);
  while (static_cast<int>(centres.size()) < k) {
    double total = 0.0;
    for (const double sum : block_sum)
      total += sum;
    if (total <= 0.0)
      break;  // fewer distinct points than k
    double pick = rng.uniform() * total;
    int chosen = n - 1;
    for (int b = 0; b < blocks; ++b) {
      if (pick > block_sum[b] && b + 1 < blocks) {
        pick -= block_sum[b];
        continue;
      }
      const int end = std::min(n, (b + 1) * BLOCK);
      for (int i = b * BLOCK; i < end; ++i) {
        if (d2[i] <= 0.0)
          continue;  // a centre's own point; rounding must not pick it twice
        chosen = i;
        pick -= d2[i];
        if (pick <= 0.0)
          break;
      }
      break;
    }
    centres.push_back(pts[chosen]);
    admit(static_cast<int>(centres.size()) - 1);
  }
  k = static_cast<int>(centres.size());
  std::vector<Eigen::Vector3d> sums(k);
  std::vector<int> counts(k);
  std::vector<std::vector<Eigen::Vector3d>> block_sums(blocks, std::vector<Eigen::Vector3d>(k));
  std::vector<std::vector<int>> block_counts(blocks, std::vector<int>(k));
  std::vector<char> moved(n, 0);
  // Hamerly's exact acceleration of Lloyd's assignment: per point an upper bound on the
  // distance to its centre and a lower bound on the distance to any other; a point whose
  // bounds prove its centre nearest is not scanned. Same labels as the plain scan.
  std::vector<double> upper(n, std::numeric_limits<double>::infinity()), lower(n, 0.0);
  std::vector<double> half_gap(k, 0.0), shift(k, 0.0);
  // Per centre, the other centres by distance: a point that must be scanned walks them outward
  // from its own centre and stops where the triangle inequality proves every centre left
  // farther than its second nearest (|p - c| >= |c - own| - |p - own|). Ties go to the lower
  // index, as in a scan in index order, so the labels are those of the full scan.
  std::vector<std::vector<std::pair<double, int>>> by_distance(k);
  auto scan = [&](int i) {
    const int own = labels[i];
    const double own_distance = upper[i];  // exact: computed just before the scan
    int best = own;
    double best_d = (pts[i] - centres[own]).squaredNorm();
    double second = std::numeric_limits<double>::infinity();
    double second_norm = second;
    for (const auto& [gap, c] : by_distance[own]) {
      if (gap - own_distance > second_norm + ROUNDING)
        break;
      const double d = (pts[i] - centres[c]).squaredNorm();
      if (d < best_d || (d == best_d && c < best)) {
        second = best_d;
        best_d = d;
        best = c;
        second_norm = std::sqrt(second);
      } else if (d < second) {
        second = d;
        second_norm = std::sqrt(second);
      }
    }
    moved[i] = labels[i] != best;
    labels[i] = best;
    upper[i] = std::sqrt(best_d);
    lower[i] = second_norm;
  };
  // How far a scan from each centre can walk: its points' largest upper bound, per block and
  // then per centre (a point of centre c never walks past 2 max upper + c's nearest gap).
  std::vector<double> reach(k, 0.0);
  std::vector<std::vector<double>> block_reach_of(blocks, std::vector<double>(k));
  for (int it = 0; it < max_iterations; ++it) {
    if (it > 0) {
      parallelFor(blocks, [&](int b) {
        auto& row = block_reach_of[b];
        std::fill(row.begin(), row.end(), 0.0);
        const int end = std::min(n, (b + 1) * BLOCK);
        for (int i = b * BLOCK; i < end; ++i)
          row[labels[i]] = std::max(row[labels[i]], upper[i]);
      });
      std::fill(reach.begin(), reach.end(), 0.0);
      for (int b = 0; b < blocks; ++b) {
        for (int c = 0; c < k; ++c)
          reach[c] = std::max(reach[c], block_reach_of[b][c]);
      }
    }
    parallelFor(k, [&](int c) {
      auto& row = by_distance[c];
      row.clear();
      double nearest = std::numeric_limits<double>::infinity();
      for (int o = 0; o < k; ++o) {
        if (o != c) {
          row.emplace_back((centres[c] - centres[o]).norm(), o);
          nearest = std::min(nearest, row.back().first);
        }
      }
      half_gap[c] = 0.5 * nearest;
      // A scan starts at a point's own centre (distance u <= reach) and its first step finds a
      // second-nearest within u + nearest: it stops before any centre farther than
      // 2 reach + nearest from its own. Only those nearer are sorted (the first pass scans
      // nothing: no row is needed). Same walk as over the whole sorted row.
      const double cutoff = it == 0 ? -1.0 : 2.0 * reach[c] + nearest + 1e-6;
      row.erase(std::partition(row.begin(), row.end(),
                               [&](const std::pair<double, int>& e) { return e.first <= cutoff; }),
                row.end());
      std::sort(row.begin(), row.end());
    });
    // Assignment: independent per point, so it runs on every core with identical results (a
    // cluster's k-means inside splitClusters' parallel loop runs on its own thread).
    forEachPoint([&](int i) {
      moved[i] = 0;
      if (it == 0) {
        // Assigned while seeding; labels start at 0, as the scan's comparison assumes.
        moved[i] = labels[i] != 0;
        upper[i] = std::sqrt(d2[i]);
        lower[i] = std::sqrt(second_d2[i]);
        return;
      }
      const double bound = std::max(half_gap[labels[i]], lower[i]);
      if (upper[i] <= bound)
        return;
      upper[i] = (pts[i] - centres[labels[i]]).norm();
      if (upper[i] <= bound)
        return;
      scan(i);
    });
    const bool changed = std::find(moved.begin(), moved.end(), 1) != moved.end();
    // Means from per-block sums added in block order: parallel, and the same on any threads.
    parallelFor(blocks, [&](int b) {
      auto& sum = block_sums[b];
      auto& count = block_counts[b];
      std::fill(sum.begin(), sum.end(), Eigen::Vector3d::Zero());
      std::fill(count.begin(), count.end(), 0);
      const int end = std::min(n, (b + 1) * BLOCK);
      for (int i = b * BLOCK; i < end; ++i) {
        sum[labels[i]] += pts[i];
        ++count[labels[i]];
      }
    });
    parallelFor(k, [&](int c) {
      sums[c].setZero();
      counts[c] = 0;
      for (int b = 0; b < blocks; ++b) {
        sums[c] += block_sums[b][c];
        counts[c] += block_counts[b][c];
      }
    });
    double max_shift = 0.0;
    for (int c = 0; c < k; ++c) {
      shift[c] = 0.0;
      if (counts[c] > 0) {
        const Eigen::Vector3d next = sums[c] / counts[c];
        shift[c] = (next - centres[c]).norm();
        centres[c] = next;
      }
      max_shift = std::max(max_shift, shift[c]);
    }
    if (!changed && it > 0)
      break;
    forEachPoint([&](int i) {
      upper[i] += shift[labels[i]];
      lower[i] -= max_shift;
    });
  }
  // Renumber so that every label in [0, k') is used (an emptied centre leaves a gap).
  std::vector<int> remap(k, -1);
  int next = 0;
  for (int& l : labels) {
    if (remap[l] < 0)
      remap[l] = next++;
    l = remap[l];
  }
  return labels;
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
