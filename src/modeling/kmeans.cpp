#include <algorithm>
#include <limits>

#include "dormant_tree_modeling/common/parallel.h"
#include "dormant_tree_modeling/common/random.h"
#include "dormant_tree_modeling/modeling/geometry_fit.h"

namespace dormant_tree_modeling {
namespace modeling {

std::vector<int> kMeans(const Points& pts, int k, int max_iterations, std::uint64_t seed) {
  const int n = static_cast<int>(pts.size());
  std::vector<int> labels(n, 0);
  k = std::clamp(k, 1, std::max(1, n));
  if (n == 0 || k == 1)
    return labels;
  Rng rng(seed);
  // k-means++ seeding: each next centre drawn with probability proportional to D^2.
  std::vector<Eigen::Vector3d> centres{pts[rng.uniformInt(0, n - 1)]};
  std::vector<double> d2(n, std::numeric_limits<double>::infinity());
  while (static_cast<int>(centres.size()) < k) {
    double total = 0.0;
    for (int i = 0; i < n; ++i) {
      d2[i] = std::min(d2[i], (pts[i] - centres.back()).squaredNorm());
      total += d2[i];
    }
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
  }
  k = static_cast<int>(centres.size());
  std::vector<Eigen::Vector3d> sums(k);
  std::vector<int> counts(k);
  std::vector<char> moved(n, 0);
  for (int it = 0; it < max_iterations; ++it) {
    // Assignment: independent per point, so it runs on every core with identical results.
    parallelFor(n, [&](int i) {
      int best = 0;
      double best_d = std::numeric_limits<double>::infinity();
      for (int c = 0; c < k; ++c) {
        const double d = (pts[i] - centres[c]).squaredNorm();
        if (d < best_d) {
          best_d = d;
          best = c;
        }
      }
      moved[i] = labels[i] != best;
      labels[i] = best;
    });
    const bool changed = std::find(moved.begin(), moved.end(), 1) != moved.end();
    std::fill(sums.begin(), sums.end(), Eigen::Vector3d::Zero());
    std::fill(counts.begin(), counts.end(), 0);
    for (int i = 0; i < n; ++i) {
      sums[labels[i]] += pts[i];
      ++counts[labels[i]];
    }
    for (int c = 0; c < k; ++c) {
      if (counts[c] > 0)
        centres[c] = sums[c] / counts[c];
    }
    if (!changed && it > 0)
      break;
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
