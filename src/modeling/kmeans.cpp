#include <algorithm>
#include <cmath>
#include <limits>

#include "dormant_tree_modeling/common/parallel.h"
#include "dormant_tree_modeling/common/random.h"
#include "dormant_tree_modeling/modeling/geometry_fit.h"

namespace dormant_tree_modeling {
namespace modeling {

namespace {
constexpr int BLOCK = 4096;  // points per task of the parallel loops
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
  auto admit = [&](int c) {
    // Same order and strict comparisons as a scan over the centres in index order.
    const Eigen::Vector3d centre = centres[c];
    forEachPoint([&](int i) {
      const double d = (pts[i] - centre).squaredNorm();
      if (d < d2[i]) {
        second_d2[i] = d2[i];
        d2[i] = d;
        labels[i] = c;
      } else if (d < second_d2[i]) {
        second_d2[i] = d;
      }
    });
  };
  admit(0);
  while (static_cast<int>(centres.size()) < k) {
    double total = 0.0;
    for (int i = 0; i < n; ++i)
      total += d2[i];
    if (total <= 0.0)
      break;  // fewer distinct points than k
    double pick = rng.uniform() * total;
    int chosen = n - 1;
    for (int i = 0; i < n; ++i) {
      pick -= d2[i];
      if (pick <= 0.0) {
        chosen = i;
        break;
      }
    }
    centres.push_back(pts[chosen]);
    admit(static_cast<int>(centres.size()) - 1);
  }
  k = static_cast<int>(centres.size());
  std::vector<Eigen::Vector3d> sums(k);
  std::vector<int> counts(k);
  std::vector<char> moved(n, 0);
  // Hamerly's exact acceleration of Lloyd's assignment: per point an upper bound on the
  // distance to its centre and a lower bound on the distance to any other; a point whose
  // bounds prove its centre nearest is not scanned. Same labels as the plain scan.
  std::vector<double> upper(n, std::numeric_limits<double>::infinity()), lower(n, 0.0);
  std::vector<double> half_gap(k, 0.0), shift(k, 0.0);
  auto scan = [&](int i) {
    int best = 0;
    double best_d = std::numeric_limits<double>::infinity(),
           second = std::numeric_limits<double>::infinity();
    for (int c = 0; c < k; ++c) {
      const double d = (pts[i] - centres[c]).squaredNorm();
      if (d < best_d) {
        second = best_d;
        best_d = d;
        best = c;
      } else if (d < second) {
        second = d;
      }
    }
    moved[i] = labels[i] != best;
    labels[i] = best;
    upper[i] = std::sqrt(best_d);
    lower[i] = std::sqrt(second);
  };
  for (int it = 0; it < max_iterations; ++it) {
    for (int c = 0; c < k; ++c) {
      double nearest = std::numeric_limits<double>::infinity();
      for (int o = 0; o < k; ++o) {
        if (o != c)
          nearest = std::min(nearest, (centres[c] - centres[o]).norm());
      }
      half_gap[c] = 0.5 * nearest;
    }
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
    std::fill(sums.begin(), sums.end(), Eigen::Vector3d::Zero());
    std::fill(counts.begin(), counts.end(), 0);
    for (int i = 0; i < n; ++i) {
      sums[labels[i]] += pts[i];
      ++counts[labels[i]];
    }
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
    for (int i = 0; i < n; ++i) {
      upper[i] += shift[labels[i]];
      lower[i] -= max_shift;
    }
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
