#include "dormant_tree_modeling/modeling/trunk_search.h"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdint>
#include <limits>
#include <numeric>
#include <unordered_map>

#include "dormant_tree_modeling/common/parallel.h"
#include "dormant_tree_modeling/common/statistics.h"
#include "dormant_tree_modeling/modeling/noise_band.h"
#include "dormant_tree_modeling/modeling/noise_bias.h"

namespace dormant_tree_modeling {
namespace modeling {

namespace {

// A trunk track scores the points between these distances (m) beyond its surface: branches.
// A post has none; a neighbour's branch is no vertical cylinder.
constexpr double BRANCH_SHELL_INNER_M = 0.05;
constexpr double BRANCH_SHELL_OUTER_M = 0.35;
constexpr double CENTRE_PRIOR_SCALE = 0.5;  // m
constexpr double GROUND_REACH = 0.3;        // m above the cloud's bottom a trunk track reaches
constexpr double SAME_TRUNK_MIN = 0.03;     // m: tracks closer than this follow one trunk
constexpr double STRAY_TIE = 0.005;         // m of mean offset per other track: strays alike
constexpr double BASE_HEIGHT = 0.6;         // m of a track's bottom that says which trunk it is
// A track whose top third is at least this share of its bottom third's radius does not taper.
// A group one of whose voting tracks neither tapers nor varies in radius (POLE_RADIUS_SPREAD)
// is a trellis post or a pole, scored at POLE_WEIGHT (one post beside a tree gathers the
// tree's branches in its shell and outscored the trunk on two test trees). One, not most:
// where a leaning tree touches a post, the post's other tracks take in the tree's bark or
// settle off its axis for a stretch and vary; no trunk track reads as a pole.
constexpr double POLE_TAPER = 0.9;
constexpr double POLE_WEIGHT = 0.5;
// A post's circles keep one radius: over a track's lower two thirds (above them a post's track
// can run onto the leader of a tree leaning on the post) their median absolute deviation is
// at most this share of their median. A trunk's taper and whorls vary it by more; at
// 12 mm of range noise a thin trunk's taper is lost in the noise, but not its variation.
constexpr double POLE_RADIUS_SPREAD = 0.025;
// A post's track ends at the post's top: after its last circle where, over POST_TOP_WINDOW
// circles around it, the median radius is within POST_TOP_CHANGE of its lower two thirds' or
// the centres' median offset from the line through their centres is at most POST_TOP_OFF_AXIS
// of that radius. Where a leaning tree's leader touches the top, the climb goes on onto the
// leader (narrower, and a post's radius and more off its axis) or around the crown (wider, and
// off it), and the track would take the tree's crown for the post's. A column of sections (a
// calibration rig's pipe) narrows on its axis. A window, since at 12 mm of noise a post's
// circles read 15 % off a few at a time.
constexpr double POST_TOP_CHANGE = 0.15;
constexpr std::size_t POST_TOP_WINDOW = 5;
constexpr double POST_TOP_OFF_AXIS = 0.5;
// The trunk's track is measured again past another column from this many circles below the
// first that comes within the band of the column's surface: the circles just below it are
// already drawn towards the column.
constexpr int COLUMN_CLIMB_BACKOFF_SLICES = 2;
constexpr double RETRY_WIDTH = 1.6;     // first circle / start radius above which a low track
                                        // is retried
constexpr double VOTING_HEIGHT = 0.75;  // share of its trunk's height a track must climb to vote
// Density columns: points counted on a COLUMN_CELL_M grid and summed over a square of
// 2 COLUMN_HALF_CELLS + 1 cells (10 cm, a young trunk's diameter and more); at most
// COLUMN_STARTS of them are tried.
constexpr double COLUMN_CELL_M = 0.02;
constexpr int COLUMN_HALF_CELLS = 2;
constexpr int COLUMN_STARTS = 3;
// A start whose track climbs this share of the clusters' height above it stands on a trunk.
constexpr double STANDING_CLIMB = 0.5;
constexpr int RETRY_MISSES = 4;               // a retry's run of missed slices that ends it
constexpr std::size_t MIN_TRACK_CIRCLES = 3;  // fewer circles are no track
// A column's retries trust each of these radii (m): with the trusted first circle's 0.6x..1.6x
// they cover 12..128 mm, young to mature apple trunks.
constexpr std::array<double, 3> COLUMN_RETRY_RADII_M = {0.02, 0.04, 0.08};

/// Range-noise guess from a cluster's cylinder-fit residuals; the slices refine it later.
double noiseGuess(const Points& pts, const Cluster& cluster) {
  std::vector<double> res;
  for (const int i : cluster.members)
    res.push_back(axisDistance(*cluster.fit, pts[i]) - cluster.fit->radius);
  return noiseFromRadialResiduals(std::move(res));
}

/// Horizontal offsets of track b from track a at a's centres up to `below` (m), where b spans
/// their height.
std::vector<double> trackOffsets(const TrackedTrunk& a, const TrackedTrunk& b,
                                 double below = std::numeric_limits<double>::infinity()) {
  std::vector<double> out;
  for (const auto& p : a.centers) {
    if (p.z() > below)
      break;
    for (std::size_t i = 0; i + 1 < b.centers.size(); ++i) {
      const Eigen::Vector3d &lo = b.centers[i], &hi = b.centers[i + 1];
      if (p.z() < lo.z() || p.z() > hi.z() || hi.z() - lo.z() < 1e-9)
        continue;
      const double t = (p.z() - lo.z()) / (hi.z() - lo.z());
      out.push_back((p.head<2>() - (lo + t * (hi - lo)).head<2>()).norm());
      break;
    }
  }
  return out;
}

/// What every track is measured against: the clusters' height range and the cloud's
/// horizontal centre (the target is the tree its crop centres on: the paper's hand crop, our
/// scan assembler's isolation).
struct SearchFrame {
  double zmin = std::numeric_limits<double>::infinity();
  double zmax = -std::numeric_limits<double>::infinity();
  Eigen::Vector2d middle = Eigen::Vector2d::Zero();
};

SearchFrame searchFrame(const Points& pts, const std::vector<Cluster>& clusters) {
  SearchFrame f;
  for (const auto& c : clusters) {
    f.zmin = std::min(f.zmin, c.centroid.z());
    f.zmax = std::max(f.zmax, c.centroid.z());
  }
  Eigen::Vector2d lo(1e300, 1e300), hi(-1e300, -1e300);
  for (const auto& p : pts) {
    lo = lo.cwiseMin(p.head<2>());
    hi = hi.cwiseMax(p.head<2>());
  }
  f.middle = 0.5 * (lo + hi);
  return f;
}

/// The circle band is the scanner's noise, one value for all starts: the median of the
/// start clusters' noise guesses (a fragment's own guess can be twice the noise, and a band
/// that thick lets a small circle on the trunk's flank outscore the trunk's own).
double trackingThreshold(const Points& pts, const std::vector<Cluster>& clusters,
                         const std::vector<TrunkStart>& starts, const ModelerConfig& config) {
  std::vector<double> guesses;
  for (const auto& s : starts) {
    if (s.cluster >= 0 && clusters[s.cluster].fit)
      guesses.push_back(noiseGuess(pts, clusters[s.cluster]));
  }
  return std::max(0.5 * config.fit.circle_threshold_m, noiseBand(median(guesses)));
}

/// How high a track climbs above its start (m), 0 without circles.
double climbAbove(const TrackedTrunk& t, const TrunkStart& start) {
  return t.centers.empty() ? 0.0 : t.centers.back().z() - start.base.z();
}

/// Whether a track stands on its start's trunk: it climbs at least STANDING_CLIMB of the
/// clusters' height above the start (`zmax`: the highest cluster centroid's z, m).
bool stands(const TrackedTrunk& t, const TrunkStart& start, double zmax) {
  return climbAbove(t, start) >= STANDING_CLIMB * (zmax - start.base.z());
}

/// Up from the start, retried from a trusted radius when the free first circle stopped it low,
/// then down to the ground.
TrackedTrunk climbFrom(const Points& pts, const PointIndex& index, const TrunkStart& start,
                       double threshold, double zmax, const ModelerConfig& config) {
  // Tracking starts upright: a fragment's fitted axis can lean by tens of degrees, and an
  // oblique first slice cuts the trunk in an ellipse. The track bends to the trunk's lean.
  const Eigen::Vector3d up = Eigen::Vector3d::UnitZ();
  TrackedTrunk tracked = trackTrunk(pts, index, start.base, up, start.radius, threshold, config);
  const auto retry = [&](double radius) {
    if (stands(tracked, start, zmax))
      return;
    TrackedTrunk again =
        trackTrunk(pts, index, start.base, up, radius, threshold, config, RETRY_MISSES, true);
    if (climbAbove(again, start) > climbAbove(tracked, start))
      tracked = std::move(again);
  };
  // The free first circle can take in what stands around the base (suckers, weeds, soil
  // pixels) and set a radius the trunk above never matches: a track that stops low after a
  // first circle much wider than its start is tried again from the start's own radius.
  if (tracked.radii.empty() || tracked.radii.front() > RETRY_WIDTH * start.radius)
    retry(start.radius);
  // A density column has no radius of its own (its guess is the cluster starts', a post's
  // among them), and mixed pixels smear a wide disc around its foot that the free circle takes:
  // a column's track that stops low is tried from each trunk size.
  if (start.from_column) {
    for (const double radius : COLUMN_RETRY_RADII_M)
      retry(radius);
  }
  if (tracked.centers.size() < 3)
    return tracked;
  // And down to the ground: where the first cluster begins is an accident of k-means.
  const TrackedTrunk down = trackTrunk(pts, index, tracked.centers.front(), -up,
                                       tracked.radii.front(), threshold, config);
  tracked.centers.insert(tracked.centers.begin(), down.centers.rbegin(), down.centers.rend());
  tracked.radii.insert(tracked.radii.begin(), down.radii.rbegin(), down.radii.rend());
  return tracked;
}

/// A track's cross-section at height z: its axis (x, y) and radius, interpolated between the
/// circles around z; nothing outside the track's span.
struct TrackSection {
  Eigen::Vector2d axis;
  double radius;
};
std::optional<TrackSection> sectionAt(const TrackedTrunk& t, double z) {
  const auto& c = t.centers;
  if (c.size() < 2 || z < c.front().z() || z > c.back().z())
    return std::nullopt;
  const auto above = std::upper_bound(c.begin() + 1, c.end() - 1, z,
                                      [](double h, const Eigen::Vector3d& q) { return h < q.z(); });
  const std::size_t i = above - c.begin();
  const double dz = c[i].z() - c[i - 1].z();
  const double f = dz > 1e-9 ? std::clamp((z - c[i - 1].z()) / dz, 0.0, 1.0) : 0.0;
  return TrackSection{c[i - 1].head<2>() + f * (c[i].head<2>() - c[i - 1].head<2>()),
                      t.radii[i - 1] + f * (t.radii[i] - t.radii[i - 1])};
}

/// How far p lies outside a track's surface, read across its axis at p's height; nothing
/// outside the track's span.
std::optional<double> surfaceGapAt(const TrackedTrunk& t, const Eigen::Vector3d& p) {
  const auto s = sectionAt(t, p.z());
  if (!s)
    return std::nullopt;
  return (p.head<2>() - s->axis).norm() - s->radius;
}

/// Where track a ran onto another column b: the index of a's first circle whose centre lies
/// inside b's surface, when the two stood clear of each other at the lowest height both reach
/// and a, not b, moved across (a's axis moved farther from there than b's); nothing otherwise.
std::optional<std::size_t> joinsOnto(const TrackedTrunk& a, const TrackedTrunk& b) {
  if (a.centers.empty() || b.centers.empty())
    return std::nullopt;
  const double z0 = std::max(a.centers.front().z(), b.centers.front().z());
  const auto a0 = sectionAt(a, z0), b0 = sectionAt(b, z0);
  if (!a0 || !b0 || (a0->axis - b0->axis).norm() <= a0->radius + b0->radius)
    return std::nullopt;
  for (std::size_t i = 0; i < a.centers.size(); ++i) {
    const auto gap = a.centers[i].z() >= z0 ? surfaceGapAt(b, a.centers[i]) : std::nullopt;
    if (!gap || *gap >= 0.0)
      continue;
    const double a_moved = (a.centers[i].head<2>() - a0->axis).norm();
    const double b_moved = (sectionAt(b, a.centers[i].z())->axis - b0->axis).norm();
    return a_moved > b_moved ? std::optional<std::size_t>(i) : std::nullopt;
  }
  return std::nullopt;
}

/// Whether track b keeps clear of track a's surface at most heights: at more than half of b's
/// circles within a's span the gap between their surfaces exceeds `band` (m). A post that a
/// leaning tree touches is clear of it below and above; a track that follows the trunk is not.
bool keepsMostlyClear(const TrackedTrunk& a, const TrackedTrunk& b, double band) {
  int shared = 0, clear = 0;
  for (std::size_t k = 0; k < b.centers.size(); ++k) {
    const auto gap = surfaceGapAt(a, b.centers[k]);
    if (!gap)
      continue;
    ++shared;
    clear += *gap - b.radii[k] > band ? 1 : 0;
  }
  return 2 * clear > shared || shared == 0;
}

/// Whether a track narrows upwards (POLE_TAPER). One too short to tell counts as tapering.
bool tapers(const TrackedTrunk& t) {
  const std::size_t third = t.radii.size() / 3;
  if (third < 3)
    return true;
  const std::vector<double> lower(t.radii.begin(), t.radii.begin() + third);
  const std::vector<double> upper(t.radii.end() - third, t.radii.end());
  return median(upper) < POLE_TAPER * median(lower);
}

/// Whether a track keeps one radius (POLE_RADIUS_SPREAD) over its lower two thirds. One too
/// short to tell does not.
bool keepsOneRadius(const TrackedTrunk& t) {
  const std::size_t third = t.radii.size() / 3;
  if (third < 3)
    return false;
  const std::vector<double> lower(t.radii.begin(), t.radii.end() - third);
  const double middle = median(lower);
  std::vector<double> deviation;
  for (const double r : lower)
    deviation.push_back(std::abs(r - middle));
  return median(std::move(deviation)) <= POLE_RADIUS_SPREAD * middle;
}

/// Whether a track reads as a post or pole: it neither tapers nor varies in radius.
bool isPole(const TrackedTrunk& t) {
  return !tapers(t) && keepsOneRadius(t);
}

/// Branch points in the shell around a track, weighted down for a track far from the crop's
/// centre and one floating above the ground. A crop centres on the tree, crown and all: the
/// track's distance is that of its centres' mean, which a leaning trunk's base is not (seed
/// 113's steep-scaffold tree leans 0.46 m over 3.3 m towards a post, its crop centres 0.45 m
/// from its base and 0.09 m from the post's).
double trackScore(const PointIndex& index, const TrackedTrunk& tracked, const SearchFrame& frame) {
  double shell = 0.0;
  for (std::size_t k = 0; k < tracked.centers.size(); k += 2) {
    const double r = tracked.radii[k];
    shell += index.countWithin(tracked.centers[k], r + BRANCH_SHELL_OUTER_M, 1 << 20) -
             index.countWithin(tracked.centers[k], r + BRANCH_SHELL_INNER_M, 1 << 20);
  }
  Eigen::Vector2d mean = Eigen::Vector2d::Zero();
  for (const auto& c : tracked.centers)
    mean += c.head<2>();
  mean /= static_cast<double>(tracked.centers.size());
  const double off_centre = (mean - frame.middle).norm() / CENTRE_PRIOR_SCALE;
  // A trunk stands on the ground: a track whose lowest slice floats above the cloud's
  // bottom is a branch or the leader's top half, whatever the branches around it.
  double lowest = 1e300;
  for (const auto& p : tracked.centers)
    lowest = std::min(lowest, p.z());
  const double floating = std::max(0.0, lowest - (frame.zmin + GROUND_REACH)) / GROUND_REACH;
  return shell * std::exp(-off_centre * off_centre) * std::exp(-floating * floating);
}

/// Tracks that stand on one base (median offset over their lowest BASE_HEIGHT below a radius)
/// are one trunk: a group index per track (-1 for none), and the tracks' mean offsets.
struct TrackGroups {
  std::vector<int> group;
  std::vector<std::vector<double>> mean_offset;
};

TrackGroups groupTracks(const std::vector<std::optional<TrackedTrunk>>& tracks) {
  const int m = static_cast<int>(tracks.size());
  TrackGroups g;
  g.mean_offset.assign(m, std::vector<double>(m, 0.0));
  g.group.assign(m, -1);
  for (int a = 0; a < m; ++a) {
    if (!tracks[a])
      continue;
    if (g.group[a] < 0)
      g.group[a] = a;
    for (int b = a + 1; b < m; ++b) {
      if (!tracks[b])
        continue;
      const auto offsets = trackOffsets(*tracks[a], *tracks[b]);
      g.mean_offset[a][b] = g.mean_offset[b][a] =
          offsets.size() < 4
              ? std::numeric_limits<double>::infinity()
              : std::accumulate(offsets.begin(), offsets.end(), 0.0) / offsets.size();
      const auto base =
          trackOffsets(*tracks[a], *tracks[b], tracks[a]->centers.front().z() + BASE_HEIGHT);
      const double same =
          std::max(SAME_TRUNK_MIN, std::min(median(tracks[a]->radii), median(tracks[b]->radii)));
      if (g.group[b] < 0 && base.size() >= 3 && median(base) < same)
        g.group[b] = g.group[a];
    }
  }
  return g;
}

/// A group's voters: its tracks that climb at least VOTING_HEIGHT of the group's height above
/// `zmin`. A track that stopped at a whorl low on the trunk neither scores nor represents it.
std::vector<char> groupVoters(const std::vector<std::optional<TrackedTrunk>>& tracks,
                              const TrackGroups& g, int group, double zmin) {
  const int m = static_cast<int>(tracks.size());
  double group_top = -std::numeric_limits<double>::infinity();
  for (int k = 0; k < m; ++k) {
    if (g.group[k] == group)
      group_top = std::max(group_top, tracks[k]->centers.back().z());
  }
  std::vector<char> voters(m, 0);
  for (int k = 0; k < m; ++k) {
    voters[k] = g.group[k] == group &&
                tracks[k]->centers.back().z() - zmin >= VOTING_HEIGHT * (group_top - zmin);
  }
  return voters;
}

/// A group's representative: among its voters that stray alike from the other voters (within
/// STRAY_TIE per other voter; two always stray alike), the one reaching highest, since a track
/// can stop early at a whorl. A short track is no judge: its offsets are read over its own
/// height only, where a track that follows a scaffold has not left the trunk yet.
int representative(const std::vector<std::optional<TrackedTrunk>>& tracks, const TrackGroups& g,
                   const std::vector<char>& voters) {
  const int m = static_cast<int>(tracks.size());
  std::vector<double> stray(m, std::numeric_limits<double>::infinity());
  double least = std::numeric_limits<double>::infinity();
  int others = -1;
  for (int k = 0; k < m; ++k) {
    if (!voters[k])
      continue;
    ++others;
    stray[k] = 0.0;
    for (int o = 0; o < m; ++o) {
      if (o != k && voters[o])
        stray[k] += std::min(g.mean_offset[k][o], 1.0);
    }
    least = std::min(least, stray[k]);
  }
  int chosen = -1;
  double highest = -std::numeric_limits<double>::infinity();
  for (int k = 0; k < m; ++k) {
    if (voters[k] && stray[k] <= least + STRAY_TIE * others &&
        tracks[k]->centers.back().z() > highest) {
      highest = tracks[k]->centers.back().z();
      chosen = k;
    }
  }
  return chosen;
}

/// Whether one of a group's voters reads as a pole (isPole).
bool readsAsPost(const std::vector<std::optional<TrackedTrunk>>& tracks,
                 const std::vector<char>& voters) {
  for (std::size_t k = 0; k < tracks.size(); ++k) {
    if (voters[k] && isPole(*tracks[k]))
      return true;
  }
  return false;
}

/// A group's score: the median of its voting tracks' (only those that climb most of the
/// group's height vote, since a track that stopped at a whorl low on the trunk has a small
/// shell and would drag its trunk below a neighbour's), at POLE_WEIGHT when one of them reads
/// as a pole. Negative when it has no voter.
double groupScore(const std::vector<std::optional<TrackedTrunk>>& tracks,
                  const std::vector<double>& scores, const std::vector<char>& voters) {
  std::vector<double> member_scores;
  for (std::size_t k = 0; k < tracks.size(); ++k) {
    if (voters[k])
      member_scores.push_back(scores[k]);
  }
  if (member_scores.empty())
    return -1.0;
  return (readsAsPost(tracks, voters) ? POLE_WEIGHT : 1.0) * median(std::move(member_scores));
}

/// The best-scoring group's representative (groupScore), or -1.
int chooseTrack(const std::vector<std::optional<TrackedTrunk>>& tracks,
                const std::vector<double>& scores, const TrackGroups& g, double zmin) {
  const int m = static_cast<int>(tracks.size());
  int chosen = -1;
  double best_score = -1.0;
  for (int group = 0; group < m; ++group) {
    const std::vector<char> voters = groupVoters(tracks, g, group, zmin);
    const double score = groupScore(tracks, scores, voters);
    if (score < 0.0 || score <= best_score)
      continue;
    best_score = score;
    chosen = representative(tracks, g, voters);
  }
  return chosen;
}

std::vector<TrunkCandidate> candidateReport(const std::vector<TrunkStart>& starts,
                                            const std::vector<std::optional<TrackedTrunk>>& tracks,
                                            const std::vector<double>& scores,
                                            const std::vector<int>& groups, int chosen) {
  std::vector<TrunkCandidate> report(starts.size());
  for (std::size_t k = 0; k < starts.size(); ++k) {
    TrunkCandidate& r = report[k];
    r.from_column = starts[k].from_column;
    if (starts[k].usable) {
      r.start = starts[k].centre;
      r.start_radius = starts[k].radius;
    }
    if (!tracks[k])
      continue;
    r.slices = static_cast<int>(tracks[k]->centers.size());
    r.bottom = tracks[k]->centers.front().z();
    r.top = tracks[k]->centers.back().z();
    r.median_radius = median(tracks[k]->radii);
    r.score = scores[k];
    r.pole = isPole(*tracks[k]);
    r.group = groups[k];
    r.chosen = static_cast<int>(k) == chosen;
  }
  return report;
}

/// Cells of the column grid, keyed by their two indices.
struct CellKey {
  std::int64_t x, y;
  bool operator==(const CellKey& o) const { return x == o.x && y == o.y; }
};
struct CellKeyHash {
  std::size_t operator()(const CellKey& k) const {
    return std::hash<std::int64_t>()(k.x * 73856093) ^ std::hash<std::int64_t>()(k.y * 19349663);
  }
};
struct ColumnCell {
  int count = 0;
  Eigen::Vector2d sum = Eigen::Vector2d::Zero();
  double lowest = std::numeric_limits<double>::infinity();
  int smoothed = 0;
};

}  // namespace

std::vector<TrunkStart> clusterTrunkStarts(const std::vector<Cluster>& clusters,
                                           const TrunkPath& path, double zmin,
                                           const ModelerConfig& config) {
  std::vector<int> picked{path.trunk.front()};
  for (int c = 0; c < static_cast<int>(clusters.size()); ++c) {
    if (c != path.trunk.front() && isTrunkBase(clusters[c], zmin, config) &&
        clusters[c].fit->radius < MAX_TRUNK_FIT_RADIUS_M)
      picked.push_back(c);
  }
  std::vector<TrunkStart> out;
  for (const int c : picked) {
    TrunkStart s;
    s.cluster = c;
    const auto& fit = clusters[c].fit;
    s.usable = fit.has_value();
    if (fit) {
      const Eigen::Vector3d axis = fit->axis.z() < 0.0 ? Eigen::Vector3d(-fit->axis) : fit->axis;
      s.base = fit->center - 0.5 * fit->length * axis;
      s.centre = fit->center;
      s.radius = fit->radius;
    }
    out.push_back(s);
  }
  return out;
}

std::vector<TrunkStart> densityColumnStarts(const Points& pts, double zmin,
                                            const std::vector<TrunkStart>& existing, double radius,
                                            const ModelerConfig& config) {
  std::unordered_map<CellKey, ColumnCell, CellKeyHash> cells;
  const double top = zmin + TRUNK_BASE_BAND_M;
  for (const auto& p : pts) {
    if (p.z() > top)
      continue;
    ColumnCell& c = cells[CellKey{static_cast<std::int64_t>(std::floor(p.x() / COLUMN_CELL_M)),
                                  static_cast<std::int64_t>(std::floor(p.y() / COLUMN_CELL_M))}];
    ++c.count;
    c.sum += p.head<2>();
    c.lowest = std::min(c.lowest, p.z());
  }
  std::vector<std::pair<CellKey, ColumnCell*>> order;
  for (auto& [key, cell] : cells) {
    for (int dx = -COLUMN_HALF_CELLS; dx <= COLUMN_HALF_CELLS; ++dx) {
      for (int dy = -COLUMN_HALF_CELLS; dy <= COLUMN_HALF_CELLS; ++dy) {
        const auto it = cells.find(CellKey{key.x + dx, key.y + dy});
        if (it != cells.end())
          cell.smoothed += it->second.count;
      }
    }
    order.emplace_back(key, &cell);
  }
  // Densest first; ties in grid order, so the result does not depend on the hash.
  std::sort(order.begin(), order.end(), [](const auto& a, const auto& b) {
    if (a.second->smoothed != b.second->smoothed)
      return a.second->smoothed > b.second->smoothed;
    return a.first.x != b.first.x ? a.first.x < b.first.x : a.first.y < b.first.y;
  });
  // A column is the densest cell within TRUNK_COLUMN_SEPARATION_M; those near a start taken
  // already (a cluster's, a denser column's) belong to its trunk.
  std::vector<Eigen::Vector2d> taken;
  for (const auto& s : existing) {
    if (s.usable)
      taken.push_back(s.base.head<2>());
  }
  std::vector<Eigen::Vector2d> peaks;
  std::vector<TrunkStart> out;
  for (const auto& [key, cell] : order) {
    if (cell->smoothed < 2 * config.graph.min_cluster_points ||
        static_cast<int>(out.size()) >= COLUMN_STARTS)
      break;
    const Eigen::Vector2d xy((key.x + 0.5) * COLUMN_CELL_M, (key.y + 0.5) * COLUMN_CELL_M);
    const auto near = [&](const Eigen::Vector2d& q) {
      return (q - xy).norm() < TRUNK_COLUMN_SEPARATION_M;
    };
    const bool shadowed = std::any_of(peaks.begin(), peaks.end(), near);
    peaks.push_back(xy);
    if (shadowed || std::any_of(taken.begin(), taken.end(), near))
      continue;
    // The start is the column's centroid at its lowest point: seen from all around, a trunk's
    // returns centre on its axis.
    double lowest = std::numeric_limits<double>::infinity();
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    for (int dx = -COLUMN_HALF_CELLS; dx <= COLUMN_HALF_CELLS; ++dx) {
      for (int dy = -COLUMN_HALF_CELLS; dy <= COLUMN_HALF_CELLS; ++dy) {
        const auto it = cells.find(CellKey{key.x + dx, key.y + dy});
        if (it != cells.end()) {
          lowest = std::min(lowest, it->second.lowest);
          sum += it->second.sum;
        }
      }
    }
    const Eigen::Vector2d centroid = sum / cell->smoothed;
    TrunkStart s;
    s.base = Eigen::Vector3d(centroid.x(), centroid.y(), lowest);
    s.centre = s.base;
    s.radius = radius;
    s.from_column = true;
    out.push_back(s);
  }
  return out;
}

namespace {

/// Tracks of starts[from..]: independent, on all cores.
void trackStarts(const Points& pts, const PointIndex& index, const std::vector<TrunkStart>& starts,
                 std::size_t from, double threshold, const SearchFrame& frame,
                 const ModelerConfig& config, std::vector<std::optional<TrackedTrunk>>* tracks) {
  tracks->resize(starts.size());
  parallelFor(static_cast<int>(starts.size() - from), [&](int i) {
    const std::size_t k = from + i;
    if (!starts[k].usable)
      return;
    TrackedTrunk tracked = climbFrom(pts, index, starts[k], threshold, frame.zmax, config);
    if (tracked.centers.size() >= MIN_TRACK_CIRCLES)
      (*tracks)[k] = std::move(tracked);
  });
}

/// Every track resumed past a whorl that ended it (resumePastWhorls). Only after the density
/// columns are chosen, on what stood before: a track around a young trunk's smear of mixed
/// pixels (a circle of 12 cm radius) ends low and leaves the trunk to its column; resumed, it
/// climbs to the top.
void resumeTracks(const Points& pts, const PointIndex& index, double threshold,
                  const ModelerConfig& config, std::vector<std::optional<TrackedTrunk>>* tracks) {
  parallelFor(static_cast<int>(tracks->size()), [&](int k) {
    if ((*tracks)[k])
      (*tracks)[k] = resumePastWhorls(pts, index, std::move(*(*tracks)[k]), threshold, config);
  });
}

/// Every track that keeps one radius cut at its post's top (endAtPostTop); one left with
/// fewer than MIN_TRACK_CIRCLES circles is no track.
void endPostsAtTheirTops(std::vector<std::optional<TrackedTrunk>>* tracks) {
  for (auto& t : *tracks) {
    if (!t)
      continue;
    endAtPostTop(&*t);
    if (t->centers.size() < MIN_TRACK_CIRCLES)
      t.reset();
  }
}

/// Each track's score (trackScore), -1 where there is no track.
std::vector<double> scoreTracks(const PointIndex& index, const std::vector<TrunkStart>& starts,
                                const SearchFrame& frame,
                                const std::vector<std::optional<TrackedTrunk>>& tracks) {
  std::vector<double> scores(starts.size(), -1.0);
  parallelFor(static_cast<int>(starts.size()), [&](int k) {
    if (tracks[k])
      scores[k] = trackScore(index, *tracks[k], frame);
  });
  return scores;
}

/// The starts whose tracks climb at least half of the clouds' height above them: what stands
/// near one is its trunk. A start whose track stopped low (on a wide clutter arc by a trunk's
/// foot) explains no column.
std::vector<TrunkStart> standingStarts(const std::vector<TrunkStart>& starts,
                                       const std::vector<std::optional<TrackedTrunk>>& tracks,
                                       const SearchFrame& frame) {
  std::vector<TrunkStart> out;
  for (std::size_t k = 0; k < starts.size(); ++k) {
    if (tracks[k] && stands(*tracks[k], starts[k], frame.zmax))
      out.push_back(starts[k]);
  }
  return out;
}

/// The representatives of the groups other than the chosen track's whose tracks stand and keep
/// mostly clear of it (trackBestTrunk's `columns`): their indices.
std::vector<int> otherColumns(const std::vector<std::optional<TrackedTrunk>>& tracks,
                              const std::vector<TrunkStart>& starts, const TrackGroups& g,
                              int chosen, double band, const SearchFrame& frame) {
  std::vector<int> out;
  for (int group = 0; group < static_cast<int>(tracks.size()); ++group) {
    if (group == g.group[chosen] ||
        std::find(g.group.begin(), g.group.end(), group) == g.group.end())
      continue;
    std::vector<char> voters = groupVoters(tracks, g, group, frame.zmin);
    // A post's column is one of its tracks that read as a post: ended at the post's top, not
    // run onto a leaning tree's leader above it.
    if (readsAsPost(tracks, voters)) {
      for (std::size_t i = 0; i < voters.size(); ++i)
        voters[i] = voters[i] && isPole(*tracks[i]);
    }
    const int k = representative(tracks, g, voters);
    if (k < 0)
      continue;
    if (stands(*tracks[k], starts[k], frame.zmax) &&
        keepsMostlyClear(*tracks[chosen], *tracks[k], band) &&
        keepsMostlyClear(*tracks[k], *tracks[chosen], band))
      out.push_back(k);
  }
  return out;
}

/// Whether p lies on or inside a track's surface, within `band` (m) of it, at a height the
/// track spans.
bool nearSurface(const TrackedTrunk& track, const Eigen::Vector3d& p, double band) {
  const auto gap = surfaceGapAt(track, p);
  return gap && *gap <= band;
}

/// Whether p lies near one of the columns' surfaces (nearSurface).
bool onAColumn(const std::vector<TrackedTrunk>& columns, const Eigen::Vector3d& p, double band) {
  return std::any_of(columns.begin(), columns.end(),
                     [&](const TrackedTrunk& c) { return nearSurface(c, p, band); });
}

/// The index of the track's first circle that comes within `band` (m) of a column's surface
/// (the two surfaces, not the centres), or the track's size.
std::size_t firstCircleAtAColumn(const TrackedTrunk& track,
                                 const std::vector<TrackedTrunk>& columns, double band) {
  for (std::size_t k = 0; k < track.centers.size(); ++k) {
    if (onAColumn(columns, track.centers[k], track.radii[k] + band))
      return k;
  }
  return track.centers.size();
}

}  // namespace

TrackedTrunk climbPastColumns(const Points& pts, TrackedTrunk track,
                              const std::vector<TrackedTrunk>& columns, double band,
                              const ModelerConfig& config) {
  const std::size_t near = firstCircleAtAColumn(track, columns, band);
  if (near >= track.centers.size() || near < static_cast<std::size_t>(COLUMN_CLIMB_BACKOFF_SLICES))
    return track;
  Points rest;
  for (const auto& p : pts) {
    if (!onAColumn(columns, p, band))
      rest.push_back(p);
  }
  const PointIndex index(rest);
  auto again = climbAgainFrom(rest, index, track, near - COLUMN_CLIMB_BACKOFF_SLICES, band, config);
  if (!again || again->centers.back().z() < track.centers.back().z() - config.trunk.slice_height_m)
    return track;
  return std::move(*again);
}

void endAtPostTop(TrackedTrunk* t) {
  if (!keepsOneRadius(*t))
    return;
  const std::size_t n = t->radii.size(), lower = n - n / 3, half = POST_TOP_WINDOW / 2;
  const double post = median(std::vector<double>(t->radii.begin(), t->radii.begin() + lower));
  Cylinder axis;
  axis.axis = principalAxis(Points(t->centers.begin(), t->centers.begin() + lower), &axis.center);
  std::vector<double> off_axis(n);
  for (std::size_t k = 0; k < n; ++k)
    off_axis[k] = axisDistance(axis, t->centers[k]);
  std::size_t top = 0;
  for (std::size_t k = 0; k < n; ++k) {
    const std::size_t from = k > half ? k - half : 0, to = std::min(n, k + half + 1);
    const auto window = [&](const std::vector<double>& v) {
      return median(std::vector<double>(v.begin() + from, v.begin() + to));
    };
    if (std::abs(window(t->radii) - post) <= POST_TOP_CHANGE * post ||
        window(off_axis) <= POST_TOP_OFF_AXIS * post)
      top = k;
  }
  t->centers.resize(top + 1);
  t->radii.resize(top + 1);
}

void cutWhereJoined(std::vector<std::optional<TrackedTrunk>>* tracks) {
  const std::size_t m = tracks->size();
  std::vector<std::size_t> keep(m, std::numeric_limits<std::size_t>::max());
  for (std::size_t a = 0; a < m; ++a) {
    for (std::size_t b = 0; b < m; ++b) {
      if (a == b || !(*tracks)[a] || !(*tracks)[b])
        continue;
      if (const auto i = joinsOnto(*(*tracks)[a], *(*tracks)[b]))
        keep[a] = std::min(keep[a], *i);
    }
  }
  for (std::size_t a = 0; a < m; ++a) {
    auto& t = (*tracks)[a];
    if (!t || keep[a] >= t->centers.size())
      continue;
    if (keep[a] < MIN_TRACK_CIRCLES) {
      t.reset();
      continue;
    }
    t->centers.resize(keep[a]);
    t->radii.resize(keep[a]);
  }
}

int chooseTrunkTrack(const std::vector<std::optional<TrackedTrunk>>& tracks,
                     const std::vector<double>& scores, double zmin, std::vector<int>* groups) {
  const TrackGroups g = groupTracks(tracks);
  if (groups)
    *groups = g.group;
  return chooseTrack(tracks, scores, g, zmin);
}

std::optional<TrackedTrunk> trackBestTrunk(const Points& pts, const PointIndex& index,
                                           const std::vector<Cluster>& clusters,
                                           const TrunkPath& path, const ModelerConfig& config,
                                           std::vector<TrunkCandidate>* report,
                                           std::vector<TrackedTrunk>* columns) {
  const SearchFrame frame = searchFrame(pts, clusters);
  std::vector<TrunkStart> starts = clusterTrunkStarts(clusters, path, frame.zmin, config);
  const double threshold = trackingThreshold(pts, clusters, starts, config);
  std::vector<std::optional<TrackedTrunk>> tracks;
  trackStarts(pts, index, starts, 0, threshold, frame, config, &tracks);
  // Then the dense columns that no standing track explains, in the same start order.
  std::vector<double> radii;
  for (const auto& s : starts) {
    if (s.usable)
      radii.push_back(s.radius);
  }
  if (!radii.empty()) {
    const std::size_t from = starts.size();
    const auto columns = densityColumnStarts(pts, frame.zmin, standingStarts(starts, tracks, frame),
                                             median(radii), config);
    starts.insert(starts.end(), columns.begin(), columns.end());
    trackStarts(pts, index, starts, from, threshold, frame, config, &tracks);
  }
  resumeTracks(pts, index, threshold, config, &tracks);
  endPostsAtTheirTops(&tracks);
  cutWhereJoined(&tracks);
  const std::vector<double> scores = scoreTracks(index, starts, frame, tracks);
  const TrackGroups groups = groupTracks(tracks);
  const int chosen = chooseTrack(tracks, scores, groups, frame.zmin);
  if (chosen >= 0)
    tracks[chosen] =
        resumePastWhorlsAndForks(pts, index, std::move(*tracks[chosen]), threshold, config);
  const std::vector<int> others =
      chosen >= 0 ? otherColumns(tracks, starts, groups, chosen, threshold, frame)
                  : std::vector<int>{};
  std::vector<TrackedTrunk> column_tracks;
  for (const int k : others)
    column_tracks.push_back(*tracks[k]);
  if (!column_tracks.empty())
    tracks[chosen] =
        climbPastColumns(pts, std::move(*tracks[chosen]), column_tracks, threshold, config);
  *report = candidateReport(starts, tracks, scores, groups.group, chosen);
  if (chosen < 0)
    return std::nullopt;
  for (const int k : others)
    (*report)[k].other_column = true;
  if (columns)
    columns->insert(columns->end(), column_tracks.begin(), column_tracks.end());
  return std::move(tracks[chosen]);
}

std::vector<char> pointsOnColumns(const Points& pts, const std::vector<TrackedTrunk>& columns,
                                  const TrackedTrunk& trunk, double band) {
  std::vector<char> on(pts.size(), 0);
  if (columns.empty())
    return on;
  parallelFor(static_cast<int>(pts.size()), [&](int i) {
    // The trunk's gap only for points on a column: most points are near none.
    on[i] = onAColumn(columns, pts[i], band) && !nearSurface(trunk, pts[i], band);
  });
  return on;
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
