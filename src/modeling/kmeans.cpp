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
constexpr double INF = std::numeric_limits<double>::infinity();

/// One k-means run: k-means++ seeding, then Lloyd's iterations with Hamerly's bounds. Points go
/// to the threads in blocks (a call per point would cost as much as its work); the points come
/// sorted by voxel, so a block is a slab of the cloud.
class KMeansRun {
 public:
  explicit KMeansRun(const Points& pts)
      : pts_(pts),
        n_(static_cast<int>(pts.size())),
        blocks_((n_ + BLOCK - 1) / BLOCK),
        labels_(n_, 0),
        d2_(n_, INF),
        second_d2_(n_, INF) {}

  /// k-means++ seeding: each next centre drawn with probability proportional to D^2. Each
  /// point's nearest and second-nearest centre are kept as the centres arrive: that is the first
  /// assignment of Lloyd's iterations, exactly, without scanning all k centres again.
  void seed(int k, Rng& rng);
  /// Lloyd's iterations until no label changes or max_iterations.
  void iterate(int max_iterations);
  /// The labels, renumbered so that every label in [0, k') is used (an emptied centre leaves a
  /// gap).
  std::vector<int> labels();

 private:
  template <typename Fn>
  void forEachPoint(const Fn& fn) {
    parallelFor(blocks_, [&](int b) {
      const int end = std::min(n_, (b + 1) * BLOCK);
      for (int i = b * BLOCK; i < end; ++i)
        fn(i);
    });
  }
  void blockBoxes();
  void admit(int c);
  int drawCentre(Rng& rng) const;
  void reachPerCentre();
  void sortNeighbours(int it);
  void assign(int it);
  void scan(int i);
  double updateMeans();

  const Points& pts_;
  const int n_;
  const int blocks_;
  int k_ = 0;
  std::vector<int> labels_;
  std::vector<Eigen::Vector3d> centres_;
  // Seeding: each point's squared distances to its nearest and second-nearest centre; per block
  // the sum of D^2 (the draw walks the blocks, then the points of one block), the largest
  // second-nearest distance and the bounding box (a block whose box is farther from a new
  // centre than all its points' second-nearest centres cannot change and is skipped).
  std::vector<double> d2_, second_d2_;
  std::vector<double> block_sum_, block_reach_;
  std::vector<Eigen::Vector3d> block_lo_, block_hi_;
  // Hamerly's exact acceleration of Lloyd's assignment: per point an upper bound on the
  // distance to its centre and a lower bound on the distance to any other; a point whose
  // bounds prove its centre nearest is not scanned. Same labels as the plain scan.
  std::vector<double> upper_, lower_, half_gap_, shift_;
  std::vector<char> moved_;
  // Per centre, the other centres by distance, and how far a scan from it can walk.
  std::vector<std::vector<std::pair<double, int>>> by_distance_;
  std::vector<double> reach_;
  std::vector<std::vector<double>> block_reach_of_;
  std::vector<std::vector<Eigen::Vector3d>> block_sums_;
  std::vector<std::vector<int>> block_counts_;
  std::vector<Eigen::Vector3d> sums_;
  std::vector<int> counts_;
};

void KMeansRun::blockBoxes() {
  block_sum_.assign(blocks_, 0.0);
  block_reach_.assign(blocks_, INF);
  block_lo_.resize(blocks_);
  block_hi_.resize(blocks_);
  parallelFor(blocks_, [&](int b) {
    const int end = std::min(n_, (b + 1) * BLOCK);
    block_lo_[b] = block_hi_[b] = pts_[b * BLOCK];
    for (int i = b * BLOCK; i < end; ++i) {
      block_lo_[b] = block_lo_[b].cwiseMin(pts_[i]);
      block_hi_[b] = block_hi_[b].cwiseMax(pts_[i]);
    }
  });
}

void KMeansRun::admit(int c) {
  // Same order and strict comparisons as a scan over the centres in index order.
  const Eigen::Vector3d centre = centres_[c];
  parallelFor(blocks_, [&](int b) {
    const Eigen::Vector3d outside =
        (block_lo_[b] - centre).cwiseMax(centre - block_hi_[b]).cwiseMax(0.0);
    if (outside.squaredNorm() >= block_reach_[b])
      return;
    const int end = std::min(n_, (b + 1) * BLOCK);
    double sum = 0.0, reach = 0.0;
    for (int i = b * BLOCK; i < end; ++i) {
      const double d = (pts_[i] - centre).squaredNorm();
      if (d < d2_[i]) {
        second_d2_[i] = d2_[i];
        d2_[i] = d;
        labels_[i] = c;
      } else if (d < second_d2_[i]) {
        second_d2_[i] = d;
      }
      sum += d2_[i];
      reach = std::max(reach, second_d2_[i]);
    }
    block_sum_[b] = sum;
    block_reach_[b] = reach;
  });
}

/// The next centre's point, drawn with probability proportional to D^2; -1 when every point
/// is a centre already (fewer distinct points than k).
int KMeansRun::drawCentre(Rng& rng) const {
  double total = 0.0;
  for (const double sum : block_sum_)
    total += sum;
  if (total <= 0.0)
    return -1;
  double pick = rng.uniform() * total;
  int chosen = n_ - 1;
  for (int b = 0; b < blocks_; ++b) {
    if (pick > block_sum_[b] && b + 1 < blocks_) {
      pick -= block_sum_[b];
      continue;
    }
    const int end = std::min(n_, (b + 1) * BLOCK);
    for (int i = b * BLOCK; i < end; ++i) {
      if (d2_[i] <= 0.0)
        continue;  // a centre's own point; rounding must not pick it twice
      chosen = i;
      pick -= d2_[i];
      if (pick <= 0.0)
        break;
    }
    break;
  }
  return chosen;
}

void KMeansRun::seed(int k, Rng& rng) {
  centres_ = {pts_[rng.uniformInt(0, n_ - 1)]};
  blockBoxes();
  admit(0);
  while (static_cast<int>(centres_.size()) < k) {
    const int chosen = drawCentre(rng);
    if (chosen < 0)
      break;
    centres_.push_back(pts_[chosen]);
    admit(static_cast<int>(centres_.size()) - 1);
  }
  k_ = static_cast<int>(centres_.size());
}

/// How far a scan from each centre can walk: its points' largest upper bound, per block and
/// then per centre (a point of centre c never walks past 2 max upper + c's nearest gap).
void KMeansRun::reachPerCentre() {
  parallelFor(blocks_, [&](int b) {
    auto& row = block_reach_of_[b];
    std::fill(row.begin(), row.end(), 0.0);
    const int end = std::min(n_, (b + 1) * BLOCK);
    for (int i = b * BLOCK; i < end; ++i)
      row[labels_[i]] = std::max(row[labels_[i]], upper_[i]);
  });
  std::fill(reach_.begin(), reach_.end(), 0.0);
  for (int b = 0; b < blocks_; ++b) {
    for (int c = 0; c < k_; ++c)
      reach_[c] = std::max(reach_[c], block_reach_of_[b][c]);
  }
}

/// Per centre, the other centres by distance: a point that must be scanned walks them outward
/// from its own centre and stops where the triangle inequality proves every centre left
/// farther than its second nearest (|p - c| >= |c - own| - |p - own|).
void KMeansRun::sortNeighbours(int it) {
  parallelFor(k_, [&](int c) {
    auto& row = by_distance_[c];
    row.clear();
    double nearest = INF;
    for (int o = 0; o < k_; ++o) {
      if (o != c) {
        row.emplace_back((centres_[c] - centres_[o]).norm(), o);
        nearest = std::min(nearest, row.back().first);
      }
    }
    half_gap_[c] = 0.5 * nearest;
    // A scan starts at a point's own centre (distance u <= reach) and its first step finds a
    // second-nearest within u + nearest: it stops before any centre farther than
    // 2 reach + nearest from its own. Only those nearer are sorted (the first pass scans
    // nothing: no row is needed). Same walk as over the whole sorted row.
    const double cutoff = it == 0 ? -1.0 : 2.0 * reach_[c] + nearest + 1e-6;
    row.erase(std::partition(row.begin(), row.end(),
                             [&](const std::pair<double, int>& e) { return e.first <= cutoff; }),
              row.end());
    std::sort(row.begin(), row.end());
  });
}

/// Ties go to the lower index, as in a scan in index order, so the labels are those of the
/// full scan.
void KMeansRun::scan(int i) {
  const int own = labels_[i];
  const double own_distance = upper_[i];  // exact: computed just before the scan
  int best = own;
  double best_d = (pts_[i] - centres_[own]).squaredNorm();
  double second = INF;
  double second_norm = second;
  for (const auto& [gap, c] : by_distance_[own]) {
    if (gap - own_distance > second_norm + ROUNDING)
      break;
    const double d = (pts_[i] - centres_[c]).squaredNorm();
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
  moved_[i] = labels_[i] != best;
  labels_[i] = best;
  upper_[i] = std::sqrt(best_d);
  lower_[i] = second_norm;
}

/// Assignment: independent per point, so it runs on every core with identical results (a
/// cluster's k-means inside splitClusters' parallel loop runs on its own thread).
void KMeansRun::assign(int it) {
  forEachPoint([&](int i) {
    moved_[i] = 0;
    if (it == 0) {
      // Assigned while seeding; labels start at 0, as the scan's comparison assumes.
      moved_[i] = labels_[i] != 0;
      upper_[i] = std::sqrt(d2_[i]);
      lower_[i] = std::sqrt(second_d2_[i]);
      return;
    }
    const double bound = std::max(half_gap_[labels_[i]], lower_[i]);
    if (upper_[i] <= bound)
      return;
    upper_[i] = (pts_[i] - centres_[labels_[i]]).norm();
    if (upper_[i] <= bound)
      return;
    scan(i);
  });
}

/// Means from per-block sums added in block order: parallel, and the same on any threads.
/// Returns the largest shift of a centre.
double KMeansRun::updateMeans() {
  parallelFor(blocks_, [&](int b) {
    auto& sum = block_sums_[b];
    auto& count = block_counts_[b];
    std::fill(sum.begin(), sum.end(), Eigen::Vector3d::Zero());
    std::fill(count.begin(), count.end(), 0);
    const int end = std::min(n_, (b + 1) * BLOCK);
    for (int i = b * BLOCK; i < end; ++i) {
      sum[labels_[i]] += pts_[i];
      ++count[labels_[i]];
    }
  });
  parallelFor(k_, [&](int c) {
    sums_[c].setZero();
    counts_[c] = 0;
    for (int b = 0; b < blocks_; ++b) {
      sums_[c] += block_sums_[b][c];
      counts_[c] += block_counts_[b][c];
    }
  });
  double max_shift = 0.0;
  for (int c = 0; c < k_; ++c) {
    shift_[c] = 0.0;
    if (counts_[c] > 0) {
      const Eigen::Vector3d next = sums_[c] / counts_[c];
      shift_[c] = (next - centres_[c]).norm();
      centres_[c] = next;
    }
    max_shift = std::max(max_shift, shift_[c]);
  }
  return max_shift;
}

void KMeansRun::iterate(int max_iterations) {
  block_sums_.assign(blocks_, std::vector<Eigen::Vector3d>(k_));
  block_counts_.assign(blocks_, std::vector<int>(k_));
  sums_.assign(k_, Eigen::Vector3d::Zero());
  counts_.assign(k_, 0);
  moved_.assign(n_, 0);
  upper_.assign(n_, INF);
  lower_.assign(n_, 0.0);
  half_gap_.assign(k_, 0.0);
  shift_.assign(k_, 0.0);
  by_distance_.assign(k_, {});
  reach_.assign(k_, 0.0);
  block_reach_of_.assign(blocks_, std::vector<double>(k_));
  for (int it = 0; it < max_iterations; ++it) {
    if (it > 0)
      reachPerCentre();
    sortNeighbours(it);
    assign(it);
    const bool changed = std::find(moved_.begin(), moved_.end(), 1) != moved_.end();
    const double max_shift = updateMeans();
    if (!changed && it > 0)
      break;
    forEachPoint([&](int i) {
      upper_[i] += shift_[labels_[i]];
      lower_[i] -= max_shift;
    });
  }
}

std::vector<int> KMeansRun::labels() {
  std::vector<int> remap(k_, -1);
  int next = 0;
  for (int& l : labels_) {
    if (remap[l] < 0)
      remap[l] = next++;
    l = remap[l];
  }
  return labels_;
}

}  // namespace

std::vector<int> kMeans(const Points& pts, int k, int max_iterations, std::uint64_t seed) {
  const int n = static_cast<int>(pts.size());
  k = std::clamp(k, 1, std::max(1, n));
  if (n == 0 || k == 1)
    return std::vector<int>(n, 0);
  Rng rng(seed);
  KMeansRun run(pts);
  run.seed(k, rng);
  run.iterate(max_iterations);
  return run.labels();
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
