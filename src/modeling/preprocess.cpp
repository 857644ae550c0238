#include "dormant_tree_modeling/modeling/preprocess.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <iterator>
#include <limits>
#include <optional>
#include <string>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/parallel.h"
#include "dormant_tree_modeling/common/random.h"
#include "dormant_tree_modeling/common/statistics.h"
#include "dormant_tree_modeling/modeling/geometry_fit.h"
#include "dormant_tree_modeling/modeling/point_index.h"

#include "cell_grid.h"

namespace dormant_tree_modeling {
namespace modeling {

namespace {

constexpr double GROUND_BAND = 0.03;  // m above the ground plane removed with it
// A plane is the ground when its returns reach at least GROUND_MIN_LENGTH along their longer
// horizontal direction (more than a trunk base is wide: the trunk step allows 0.4 m of radius)
// and GROUND_MIN_WIDTH across it (more than a wire or a branch lying low). A tree's crop
// across the row can hold a strip of ground narrower than its length.
constexpr double GROUND_MIN_LENGTH = 0.8;     // m
constexpr double GROUND_MIN_WIDTH = 0.3;      // m
constexpr std::size_t GROUND_SAMPLE = 50000;  // low points that score a ground hypothesis
constexpr double SPACING_CELL = 0.02;         // m, grid of medianSpacing() without an index
// Above max_modeled_points the grid grows by at least this factor per round, from at least
// MIN_CAPPED_VOXEL_M (a configured voxel_size of 0 keeps every point until the cap).
constexpr double MIN_VOXEL_GROWTH = 1.25;
constexpr double MIN_CAPPED_VOXEL_M = 0.001;
// Far outliers: the bulk's box is the 1st to 99th percentile on each axis (from a sample of
// at most FAR_OUTLIER_SAMPLE points); a point more than FAR_OUTLIER_MARGIN box extents (and at
// least FAR_OUTLIER_MIN_MARGIN_M) outside it is a stray, not a part of an orchard scene.
constexpr double FAR_OUTLIER_QUANTILE = 0.01;
constexpr double FAR_OUTLIER_MARGIN = 10.0;
constexpr double FAR_OUTLIER_MIN_MARGIN_M = 100.0;
constexpr std::size_t FAR_OUTLIER_SAMPLE = 100000;
constexpr double WIRE_BAND = 0.025;          // m around a wire line: its noisy returns
constexpr double WIRE_NEIGHBOURHOOD = 0.10;  // m, for the linearity test
constexpr double WIRE_LINEARITY = 0.1;       // second / first eigenvalue below this: a line
constexpr double WIRE_MAX_GAP = 0.35;        // m: a wire's returns are never sparser than this
constexpr double WIRE_MAX_TILT = 15.0 * M_PI / 180.0;
constexpr double WIRE_MAX_CROSSING = 10.0 * M_PI / 180.0;  // from the row's direction
constexpr int MAX_WIRES = 10;
constexpr int WIRE_HYPOTHESES = 300;         // lines sampled per wire searched
constexpr std::size_t MIN_WIRE_SUPPORT = 5;  // line-like candidates on a line worth judging
constexpr double WIRE_TEST_VOXEL = 0.01;     // m
constexpr int WIRE_REFINE_ROUNDS = 2;        // fits of a sampled line to the points near it
// Seen along the row, a wire is a spot a few cm across: a grid of WIRE_BAND cells over every
// WIRE_SPOT_STRIDE-th point, whose WIRE_SPOTS_TRIED densest cells are tried as wires.
constexpr std::size_t WIRE_SPOT_STRIDE = 4;
constexpr int WIRE_SPOTS_TRIED = 30;
// A line is a wire only when returns fill this share of the WIRE_COVER_BIN bins along its
// longest run: a line stringing branches and trunks together along the row has gaps, and so
// has a sampled line a few degrees off a wire, which would cut through the trunk it passes.
constexpr double WIRE_COVER_BIN = 0.02;  // m
constexpr double WIRE_MIN_COVER = 0.95;
// The wires of a trellis are decimetres apart: a spot this near a wire's line is its fringe.
constexpr double WIRE_SEPARATION = 2.0 * WIRE_BAND;
// A crop cut tight around a narrow tree holds its wires shorter than any wire length: a line
// that runs across this share of the cloud's extent along it, edge to edge, is as long as a
// wire there can be (a branch ends at its trunk; two in line do not fill WIRE_MIN_COVER).
constexpr double WIRE_CROP_SPAN = 0.9;

/// Downsamples pts again on coarser grids until at most `cap` are left.
/// @param voxel the grid pts were downsampled on (m); receives the grid used
/// @returns how many points the coarser grids merged away
std::size_t capPoints(Points& pts, std::size_t cap, double* voxel) {
  const std::size_t before = pts.size();
  while (pts.size() > cap) {
    // A scanned surface's count falls with the square of the grid; a cloud filling a volume
    // falls faster, so the loop ends within a few rounds either way.
    const double shrink = std::sqrt(static_cast<double>(pts.size()) / static_cast<double>(cap));
    *voxel = std::max(*voxel, MIN_CAPPED_VOXEL_M) * std::max(shrink, MIN_VOXEL_GROWTH);
    pts = voxelDownsample(pts, *voxel);
  }
  return before - pts.size();
}

/// The extents (m) of points' horizontal positions along their principal direction and across
/// it, longer first.
Eigen::Vector2d horizontalExtents(const Points& pts, const std::vector<int>& idx) {
  Points flat;
  for (const int i : idx)
    flat.emplace_back(pts[i].x(), pts[i].y(), 0.0);
  const Eigen::Vector3d along = principalAxis(flat);
  const Eigen::Vector3d across = Eigen::Vector3d::UnitZ().cross(along);
  Eigen::Vector2d lo = Eigen::Vector2d::Constant(1e300), hi = -lo;
  for (const auto& p : flat) {
    const Eigen::Vector2d q(p.dot(along), p.dot(across));
    lo = lo.cwiseMin(q);
    hi = hi.cwiseMax(q);
  }
  const Eigen::Vector2d e = hi - lo;
  return Eigen::Vector2d(e.maxCoeff(), e.minCoeff());
}

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
  // The plane must be long and wide: a trunk base, a wire or a low branch is not the ground.
  std::vector<int> on;
  for (const int i : low) {
    if (std::abs(best_n.dot(pts[i]) + best_d) < 0.02)
      on.push_back(i);
  }
  if (best_count * stride < 100 || on.empty())
    return 0;
  const Eigen::Vector2d extents = horizontalExtents(pts, on);
  if (extents[0] < GROUND_MIN_LENGTH || extents[1] < GROUND_MIN_WIDTH)
    return 0;
  const std::size_t before = pts.size();
  pts.erase(std::remove_if(
                pts.begin(), pts.end(),
                [&](const Eigen::Vector3d& p) { return best_n.dot(p) + best_d < GROUND_BAND; }),
            pts.end());
  return before - pts.size();
}

/// Longest run of projections along a line without a gap above WIRE_MAX_GAP; sorts t.
/// @param from receives the index in t where the run starts (may be null)
double longestRun(std::vector<double>& t, std::size_t* from = nullptr) {
  if (t.empty())
    return 0.0;
  std::sort(t.begin(), t.end());
  double best = 0.0;
  std::size_t start = 0, best_start = 0;
  for (std::size_t i = 1; i < t.size(); ++i) {
    if (t[i] - t[i - 1] > WIRE_MAX_GAP)
      start = i;
    if (t[i] - t[start] > best) {
      best = t[i] - t[start];
      best_start = start;
    }
  }
  if (from)
    *from = best_start;
  return best;
}

/// The share of WIRE_COVER_BIN bins along a run that hold a projection.
/// @param t projections, sorted (longestRun sorts them)
/// @param first index in t where the run starts
/// @param run the run's length
double runCover(const std::vector<double>& t, std::size_t first, double run) {
  if (t.empty())
    return 0.0;
  const double start = t[first];
  const auto bins = static_cast<std::size_t>(run / WIRE_COVER_BIN) + 1;
  std::vector<char> held(bins, 0);
  for (std::size_t i = first; i < t.size() && t[i] <= start + run; ++i)
    held[std::min(bins - 1, static_cast<std::size_t>((t[i] - start) / WIRE_COVER_BIN))] = 1;
  return static_cast<double>(std::count(held.begin(), held.end(), 1)) / static_cast<double>(bins);
}

/// Candidates: points whose 10 cm neighbourhood is a thin, near-horizontal line (a noisy wire
/// is a ribbon a few cm wide, still much narrower than long). Checked on a sample of points,
/// against a 1 cm grid of the cloud: the shape of a 10 cm ball needs no finer sampling. The
/// ball is gathered from the 27 cells of a 10 cm grid around the point (cheaper than a k-d tree
/// for 20000 balls of hundreds of points each; the same ball, its edge measured in double
/// precision where the single-precision tree rounded).
std::vector<int> lineLikePoints(const Points& pts) {
  const Points coarse = voxelDownsample(pts, WIRE_TEST_VOXEL);
  const detail::CellKeys grid = detail::sortedByCell(coarse, WIRE_NEIGHBOURHOOD);
  const std::size_t stride = std::max<std::size_t>(1, pts.size() / 20000);
  const int samples = static_cast<int>((pts.size() + stride - 1) / stride);
  std::vector<char> linear(samples, 0);
  parallelFor(samples, [&](int k) {
    const Eigen::Vector3d& p = pts[static_cast<std::size_t>(k) * stride];
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
    int count = 0;
    detail::forEachInCube(grid, p, 1, [&](int j) {
      const Eigen::Vector3d d = coarse[j] - p;  // small offsets: a one-pass covariance is exact
      if (d.squaredNorm() <= WIRE_NEIGHBOURHOOD * WIRE_NEIGHBOURHOOD) {
        sum += d;
        outer.noalias() += d * d.transpose();
        ++count;
      }
      return true;
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
  return candidates;
}

/// A line through `origin` along unit `direction`, and how many candidates lie within
/// WIRE_BAND of it.
struct WireLine {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
  std::size_t support = 0;

  bool near(const Eigen::Vector3d& p) const { return squaredDistance(p) < WIRE_BAND * WIRE_BAND; }

  double squaredDistance(const Eigen::Vector3d& p) const {
    const Eigen::Vector3d w = p - origin;
    return (w - w.dot(direction) * direction).squaredNorm();
  }
};

/// The best-supported of WIRE_HYPOTHESES near-horizontal lines through two candidates at least
/// 30 cm apart (support 0 when none was).
WireLine bestLine(const Points& pts, const std::vector<int>& candidates, Rng& rng) {
  const int n = static_cast<int>(candidates.size());
  WireLine best;
  for (int it = 0; it < WIRE_HYPOTHESES; ++it) {
    const Eigen::Vector3d& a = pts[candidates[rng.uniformInt(0, n - 1)]];
    const Eigen::Vector3d& b = pts[candidates[rng.uniformInt(0, n - 1)]];
    const Eigen::Vector3d d = b - a;
    if (d.norm() < 0.3 || std::abs(d.normalized().z()) > std::sin(WIRE_MAX_TILT))
      continue;
    WireLine line{a, d.normalized()};
    for (const int i : candidates)
      line.support += line.near(pts[i]);
    if (line.support > best.support)
      best = line;
  }
  return best;
}

/// A line through two sampled noisy returns is a few degrees off its wire, centimetres off it a
/// metre away, and would leave the wire's far parts behind: the line is fitted to the points
/// near it, and again to those near the fit.
WireLine refineLine(const Points& pts, WireLine line) {
  for (int round = 0; round < WIRE_REFINE_ROUNDS; ++round) {
    Points near;
    for (const auto& p : pts) {
      if (line.near(p))
        near.push_back(p);
    }
    if (near.size() < MIN_WIRE_SUPPORT)
      break;
    Eigen::Vector3d centroid;
    const Eigen::Vector3d direction = principalAxis(near, &centroid);
    if (std::abs(direction.z()) > std::sin(WIRE_MAX_TILT))
      break;
    line.origin = centroid;
    line.direction = direction;
  }
  return line;
}

/// The points near a line (indices), and the length of their longest run along it without a
/// gap over WIRE_MAX_GAP.
/// @param cover receives the share of the run's bins holding a return (may be null)
std::vector<int> lineRun(const Points& pts, const WireLine& line, double* run,
                         double* cover = nullptr) {
  std::vector<double> along;
  std::vector<int> inliers;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (line.near(pts[i])) {
      inliers.push_back(static_cast<int>(i));
      along.push_back((pts[i] - line.origin).dot(line.direction));
    }
  }
  std::size_t first = 0;
  *run = longestRun(along, &first);
  if (cover)
    *cover = runCover(along, first, *run);
  return inliers;
}

/// Whether a run (m) along a line is as long as a wire: min_length, or WIRE_CROP_SPAN of the
/// cloud's extent along the line where the cloud is shorter. The extent, a pass over the
/// cloud, is read only for runs under min_length.
bool wireLong(const Points& pts, const WireLine& line, double run, double min_length) {
  if (run >= min_length)
    return true;
  double lo = std::numeric_limits<double>::infinity(), hi = -lo;
  for (const auto& p : pts) {
    const double t = p.dot(line.direction);
    lo = std::min(lo, t);
    hi = std::max(hi, t);
  }
  return hi > lo && run >= WIRE_CROP_SPAN * (hi - lo);
}

/// Keeps the candidates off the line: whatever the verdict, those on it are settled.
void settle(std::vector<int>& candidates, const Points& pts, const WireLine& line) {
  std::vector<int> rest;
  for (const int i : candidates) {
    if (!line.near(pts[i]))
      rest.push_back(i);
  }
  candidates.swap(rest);
}

/// A wire found: its direction and its points (indices).
struct FoundWire {
  Eigen::Vector3d direction;
  std::vector<int> points;
  WireLine line;
};

/// The wires of a row are parallel: the direction most of the lines found share is the row's,
/// and a "wire" across it is a pair of opposite branches in line (thick ones return more points
/// than a wire: the count alone does not tell). Returns the lines found along the row.
std::vector<FoundWire> alongTheRow(std::vector<FoundWire> found) {
  const auto parallel = [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
    return std::abs(a.dot(b)) >= std::cos(WIRE_MAX_CROSSING);
  };
  std::size_t strongest = 0, best_votes = 0;
  for (std::size_t k = 0; k < found.size(); ++k) {
    std::size_t votes = 0;
    for (const auto& other : found)
      votes += parallel(found[k].direction, other.direction);
    if (votes > best_votes ||
        (votes == best_votes && found[k].points.size() > found[strongest].points.size())) {
      best_votes = votes;
      strongest = k;
    }
  }
  std::vector<FoundWire> out;
  for (auto& f : found) {
    if (parallel(f.direction, found[strongest].direction))
      out.push_back(std::move(f));
  }
  return out;
}

/// The points of the cloud seen along the row: every WIRE_SPOT_STRIDE-th point not on a wire
/// found, keyed by its WIRE_BAND cell across the row, sorted by key.
struct AlongTheRow {
  Eigen::Vector3d along, side, up;
  std::vector<std::pair<std::int64_t, int>> keyed;

  AlongTheRow(const Points& pts, const Eigen::Vector3d& direction, const std::vector<char>& taken)
      : along(direction.normalized()),
        side(Eigen::Vector3d::UnitZ().cross(along).normalized()),
        up(along.cross(side)) {
    for (std::size_t i = 0; i < pts.size(); i += WIRE_SPOT_STRIDE) {
      if (!taken[i])
        keyed.emplace_back(key(pts[i]), static_cast<int>(i));
    }
    std::sort(keyed.begin(), keyed.end());
  }

  std::int64_t key(const Eigen::Vector3d& p) const {
    const auto a = static_cast<std::int64_t>(std::floor(p.dot(side) / WIRE_BAND));
    const auto b = static_cast<std::int64_t>(std::floor(p.dot(up) / WIRE_BAND));
    return a * (std::int64_t{1} << 32) + b;  // a shift of a negative a is undefined
  }

  /// The first keyed entry of each cell, the densest cells first.
  std::vector<std::size_t> densestCells() const {
    std::vector<std::pair<std::size_t, std::size_t>> cells;  // count, first entry
    for (std::size_t i = 0; i < keyed.size();) {
      std::size_t j = i;
      while (j < keyed.size() && keyed[j].first == keyed[i].first)
        ++j;
      cells.emplace_back(j - i, i);
      i = j;
    }
    std::sort(cells.begin(), cells.end(), std::greater<>());
    std::vector<std::size_t> first;
    for (const auto& c : cells)
      first.push_back(c.second);
    return first;
  }
};

/// The line along the row through the centroid of the cell starting at keyed entry `first`.
WireLine spotLine(const Points& pts, const AlongTheRow& row, std::size_t first) {
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  int count = 0;
  for (std::size_t i = first; i < row.keyed.size() && row.keyed[i].first == row.keyed[first].first;
       ++i, ++count)
    sum += pts[row.keyed[i].second];
  return WireLine{sum / count, row.along, static_cast<std::size_t>(count)};
}

/// The longest run along a spot's line of the row's sample: a cheap first look, since most
/// dense spots are a trunk or a branch seen end on.
double sampleRun(const Points& pts, const AlongTheRow& row, const WireLine& spot) {
  std::vector<double> along;
  for (const auto& entry : row.keyed) {
    const Eigen::Vector3d& p = pts[entry.second];
    if (spot.near(p))
      along.push_back((p - spot.origin).dot(spot.direction));
  }
  return longestRun(along);
}

/// Wires the line search missed: branches trained along a wire fill its neighbourhood, and its
/// returns there are no local line. Seen along the row, every wire is a dense spot: the densest
/// spots are tried as lines parallel to the wires found, judged as those were.
void addParallelWires(const Points& pts, double min_length, std::vector<FoundWire>& wires) {
  std::vector<char> taken(pts.size(), 0);
  const FoundWire* strongest = &wires.front();
  for (const auto& w : wires) {
    for (const int i : w.points)
      taken[i] = 1;
    if (w.points.size() > strongest->points.size())
      strongest = &w;
  }
  const AlongTheRow row(pts, strongest->direction, taken);
  std::vector<WireLine> lines;
  for (const auto& w : wires)
    lines.push_back(w.line);
  int tried = 0;
  for (const std::size_t first : row.densestCells()) {
    if (tried >= WIRE_SPOTS_TRIED)
      break;
    const WireLine spot = spotLine(pts, row, first);
    const auto known = [&](const WireLine& l) {
      return l.squaredDistance(spot.origin) < WIRE_SEPARATION * WIRE_SEPARATION;
    };
    if (std::any_of(lines.begin(), lines.end(), known))
      continue;
    ++tried;
    if (!wireLong(pts, spot, sampleRun(pts, row, spot), min_length))
      continue;
    const WireLine line = refineLine(pts, spot);
    if (std::abs(line.direction.dot(row.along)) < std::cos(WIRE_MAX_CROSSING))
      continue;
    double run = 0.0, cover = 0.0;
    std::vector<int> inliers = lineRun(pts, line, &run, &cover);
    lines.push_back(line);
    if (wireLong(pts, line, run, min_length) && cover >= WIRE_MIN_COVER)
      wires.push_back({line.direction, std::move(inliers), line});
  }
}

std::size_t removeWires(Points& pts, double min_length, std::uint64_t seed,
                        std::vector<Eigen::Vector3d>* directions) {
  if (pts.size() < 100)
    return 0;
  std::vector<int> candidates = lineLikePoints(pts);
  Rng rng(seed);
  std::vector<FoundWire> found;
  for (int wire = 0; wire < MAX_WIRES && candidates.size() >= 10; ++wire) {
    const WireLine line = bestLine(pts, candidates, rng);
    if (line.support < MIN_WIRE_SUPPORT)
      break;
    double run = 0.0, cover = 0.0;
    std::vector<int> inliers = lineRun(pts, line, &run, &cover);
    settle(candidates, pts, line);
    if (!wireLong(pts, line, run, min_length) || cover < WIRE_MIN_COVER)
      continue;
    // Two sampled points fix the line to a few degrees; all its points to a fraction of one.
    Points points;
    for (const int i : inliers)
      points.push_back(pts[i]);
    found.push_back({principalAxis(points), std::move(inliers), line});
  }
  std::vector<FoundWire> wires = alongTheRow(std::move(found));
  if (!wires.empty())
    addParallelWires(pts, min_length, wires);
  std::size_t removed = 0;
  std::vector<char> drop(pts.size(), 0);
  for (const auto& wire : wires) {
    directions->push_back(wire.direction);
    for (const int i : wire.points) {
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

/// The sample medianSpacing() measures: every stride-th point, about 2000.
std::size_t spacingStride(std::size_t n) {
  return std::max<std::size_t>(1, n / 2000);
}

/// medianSpacing() from a grid of the points (any cell size; the same neighbours as the index).
double spacingFromGrid(const Points& pts, const detail::CellKeys& grid) {
  std::vector<double> d;
  for (std::size_t i = 0; i < pts.size(); i += spacingStride(pts.size()))
    d.push_back(detail::nearestDistance(grid, pts, i));
  return median(std::move(d));
}

/// floatingMask(); `counting`, when given, is a grid of pts with cells of at least
/// detail::cellForRadius(radius).
std::vector<char> floatingMaskWith(const Points& pts, double radius, int min_neighbors,
                                   const detail::CellKeys* counting) {
  std::vector<char> mask(pts.size(), 0);
  // Cells of edge h = 0.95 radius / sqrt(6): any point of a cell is within the radius of any
  // point of the same cell or of a face-adjacent one (at most h sqrt(6) apart). A cell whose
  // block of seven holds more than min_neighbors points settles all its points without a
  // count (most points of a dense scan); only the others are counted, in a grid of cells of
  // the radius. Same answer as counting every point with the k-d tree.
  const double cell = 0.95 * radius / std::sqrt(6.0);
  const detail::CellKeys grid = detail::sortedByCell(pts, cell);
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
  std::optional<detail::CellKeys> own;
  if (!counting)
    counting = &own.emplace(detail::sortedByCell(pts, detail::cellForRadius(radius)));
  parallelFor(static_cast<int>(open.size()), [&](int k) {
    const int i = open[k];
    mask[i] =
        detail::countWithin(*counting, pts, pts[i], radius, min_neighbors + 1) <= min_neighbors;
  });
  return mask;
}

/// True for a point outside the bulk's box by more than the far-outlier margin.
class FarOutlierTest {
 public:
  explicit FarOutlierTest(const Points& pts) {
    Eigen::Vector3d lo, hi;
    for (int a = 0; a < 3; ++a) {
      std::vector<double> sample = axisSample(pts, a, FAR_OUTLIER_SAMPLE);
      lo(a) = quantileInPlace(sample, FAR_OUTLIER_QUANTILE);
      hi(a) = quantileInPlace(sample, 1.0 - FAR_OUTLIER_QUANTILE);
    }
    const Eigen::Vector3d margin =
        (FAR_OUTLIER_MARGIN * (hi - lo))
            .cwiseMax(Eigen::Vector3d::Constant(FAR_OUTLIER_MIN_MARGIN_M));
    min_ = lo - margin;
    max_ = hi + margin;
  }
  bool operator()(const Eigen::Vector3d& p) const {
    return (p.array() < min_.array()).any() || (p.array() > max_.array()).any();
  }

 private:
  Eigen::Vector3d min_, max_;
};

}  // namespace

std::size_t removeFarOutliers(Points& pts) {
  if (pts.size() < 2)
    return 0;
  const FarOutlierTest far(pts);
  const std::size_t before = pts.size();
  pts.erase(std::remove_if(pts.begin(), pts.end(), far), pts.end());
  return before - pts.size();
}

double medianSpacing(const Points& pts) {
  if (pts.size() < 2)
    return 0.0;
  return spacingFromGrid(pts, detail::sortedByCell(pts, SPACING_CELL));
}

double medianSpacing(const Points& pts, const PointIndex& index) {
  if (pts.size() < 2)
    return 0.0;
  std::vector<double> d;
  for (std::size_t i = 0; i < pts.size(); i += spacingStride(pts.size())) {
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
  const auto keyed = detail::sortedByCell(pts, voxel).keyed;
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
  return floatingMaskWith(pts, radius, min_neighbors, nullptr);
}

Points preprocess(const Points& pts, const ModelerConfig& config, PreprocessStats* stats) {
  PreprocessStats s;
  s.input = pts.size();
  // The bulk is copied only when there are strays to drop: a whole scan is hundreds of MB.
  Points bulk;
  if (pts.size() >= 2) {
    const FarOutlierTest far(pts);
    s.far_outliers = static_cast<std::size_t>(std::count_if(pts.begin(), pts.end(), far));
    if (s.far_outliers > 0) {
      bulk.reserve(pts.size() - s.far_outliers);
      std::remove_copy_if(pts.begin(), pts.end(), std::back_inserter(bulk), far);
    }
  }
  s.voxel_size = config.preprocess.voxel_size_m;
  Points out = voxelDownsample(s.far_outliers > 0 ? bulk : pts, s.voxel_size);
  Points().swap(bulk);
  s.after_voxel = out.size();
  if (config.preprocess.remove_clutter) {
    double radius = config.preprocess.floating_radius_m;
    // One grid for the spacing and, when the radius stays the configured one, the counts.
    std::optional<detail::CellKeys> grid;
    if (config.noise.derive_parameters && out.size() >= 2) {
      // Sparse clouds (terrestrial scans of whole trees, a few cm between returns) would lose
      // everything to a fixed radius: scale it with the median nearest-neighbour spacing.
      grid.emplace(detail::sortedByCell(out, detail::cellForRadius(radius)));
      radius = std::max(radius, 3.0 * spacingFromGrid(out, *grid));
    }
    s.floating_radius = radius;
    const bool reuse = grid && grid->cell >= detail::cellForRadius(radius);
    const auto mask = floatingMaskWith(out, radius, config.preprocess.floating_min_neighbors,
                                       reuse ? &*grid : nullptr);

    Points kept;
    for (std::size_t i = 0; i < out.size(); ++i) {
      if (!mask[i])
        kept.push_back(out[i]);
    }
    s.floating = out.size() - kept.size();
    out.swap(kept);
    s.ground = removeGround(out, config.seed + 11);
    s.wires =
        removeWires(out, config.preprocess.wire_min_length_m, config.seed + 13, &s.wire_directions);
  }
  s.capped = capPoints(out, static_cast<std::size_t>(config.preprocess.max_points), &s.voxel_size);
  if (stats)
    *stats = s;
  return out;
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
