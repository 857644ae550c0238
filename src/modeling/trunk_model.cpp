#include "dormant_tree_modeling/modeling/trunk_model.h"

#include <Eigen/Geometry>

#include <algorithm>
#include <cmath>
#include <iterator>
#include <limits>
#include <optional>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/parallel.h"
#include "dormant_tree_modeling/common/statistics.h"
#include "dormant_tree_modeling/modeling/noise_band.h"
#include "dormant_tree_modeling/modeling/noise_bias.h"
#include "dormant_tree_modeling/modeling/point_index.h"
#include "dormant_tree_modeling/modeling/taper_profile.h"

namespace dormant_tree_modeling {
namespace modeling {

namespace {

constexpr double DEG = M_PI / 180.0;
constexpr double ZERO_SLOPE = 0.05;  // |d eta_share| below this is a flat eta
constexpr int MIN_SLICE_POINTS = 12;
constexpr double MAX_TRUNK_RADIUS = 0.4;
constexpr double TAPER_SWELL = 0.1;  // a trunk segment may be this much thicker than the one below
constexpr double FIRST_WINDOW = 0.25;   // m around a track's start searched for its first circle
constexpr int TRIMMED_MEAN_ROUNDS = 4;  // re-centrings of a noisy slice's trimmed mean
// A slice whose noise sigma exceeds this share of its radius is a disc to a circle band: it
// is centred on its trimmed mean, not on a RANSAC circle.
constexpr double NOISY_SLICE_SHARE = 0.2;
// A noisy slice's ring centre replaces its trimmed mean when they lie this many noise sigmas
// apart: further than the noise moves either, so something beside the trunk pulls the mean.
constexpr double RING_DISAGREEMENT_SIGMAS = 2.0;
// Robust sigmas under and over the taper profile a slice may read and stay in its fit: slices
// through branch bases read wide, never narrow.
constexpr double TAPER_BELOW = 2.5;
constexpr double TAPER_ABOVE = 2.0;
// From this estimated noise on, circles through branch bases and clutter outnumber the honest
// slices' scatter: only slices within one robust sigma above the profile stay in its fit.
constexpr double TAPER_NOISY_SIGMA = 0.010;
constexpr double TAPER_ABOVE_NOISY = 1.0;
// Arc length (m) either side of a slice over which the track's radii give its local radius:
// three slices, as the running median of expectedRadii.
constexpr double AXIS_RADIUS_WINDOW = 0.15;
// A slice circle's centre lies within this many local radii of the centreline: the circle
// holds the axis. A circle through the leader and scaffolds on one side of it holds more
// returns than the leader's own, and its centre lies between them, a radius or more off.
constexpr double SLICE_CENTRE_RADII = 0.3;
// The range noise is read on slices whose circle is at most this many times the track's local
// radius. Honest slices read within a fifth of it; a circle through a whorl's branch bases or
// around a scaffold beside the leader reads 1.5-2.5 times it, and its residuals measure the
// misfit, about twice the scanner's noise.
constexpr double NOISE_TRACK_RADII = 1.5;
// A track that ends is resumed past the pull of a whorl: its last RESUME_BACKOFF_SLICES
// accepted circles are dropped (a whorl's branch bases pull a slice's centre aside, and the
// track's direction with it, until the trunk's own circle lies outside its window), and the
// climb goes on above the track's end along the line through the RESUME_LINE_SLICES circles
// beneath them, at most MAX_RESUMES times.
constexpr int RESUME_BACKOFF_SLICES = 2;
// Only a pull is resumed: the track's last circle lies more than this share of the radius off
// the line (a track that ran out of trunk, into a crown of thin forks, ends on its line).
constexpr double RESUME_PULL_RADII = 0.5;
constexpr int RESUME_LINE_SLICES = 6;
constexpr int MAX_RESUMES = 3;
// A track that took a branch at a fork (a steep scaffold nearly as thick as the leader and
// scanned more densely) turns off the leader's line and ends where the branch thins out, up to
// FORK_MAX_BACKOFF_M above the fork: 50 cm for a 20 mm scaffold leaving at 24 degrees, 80 cm
// for a 27 mm one leaving at 18. It is resumed from each circle that far below its end, a
// climb along the line beneath starting FORK_SKIP_M above that circle: there a branch leaving
// at 20 degrees or more stands 3.6 cm or more off the leader's axis, clear of a young leader
// (their radii sum to 2-3 cm), and no longer draws the climb's first circle.
constexpr double FORK_MAX_BACKOFF_M = 1.0;
constexpr double FORK_SKIP_M = 0.1;
// The trunk's axis at each height is a polynomial in the height through the circle centres
// (the track's, then the slices') within a window around it. How local is chosen by the
// centres themselves: each smoothing predicts every centre from the others (leave one out),
// and a more local one replaces a stiffer one only when its median miss is at most
// AXIS_LOCAL_GAIN of the stiffer one's. A crooked leader sways with a wavelength of a metre or
// more, and only a window of a few decimetres follows it (seed 140's crooked tree at 6 mm:
// one cubic over the trunk missed its centres by 48 mm, quadratics over 50 cm by 5); where the
// centres scatter without a trend (the real adtree_tree1 trunk among its crown's forks: 12-20
// mm whatever the window), the stiff cubic stays.
struct AxisSmoothing {
  double half_window_m;  ///< centres within this height of the point; infinite: all of them
  int degree;
};
constexpr AxisSmoothing AXIS_SMOOTHINGS[] = {  // stiffest first
    {std::numeric_limits<double>::infinity(), 3},
    {1.0, 2},
    {0.5, 2},
    {0.25, 2}};
constexpr double AXIS_LOCAL_GAIN = 0.5;
// Misses under this are within any circle centre's scatter: no smoothing is more local for them.
constexpr double AXIS_MIN_MISS_M = 0.002;
// A centre off a fit by more than AXIS_OUTLIER_MEDIANS median distances (at least
// AXIS_OUTLIER_FLOOR_M) is pulled aside by a branch: it is dropped and the fit done again, in
// AXIS_FIT_ROUNDS rounds, unless fewer than AXIS_MIN_KEPT would stay.
constexpr int AXIS_FIT_ROUNDS = 3;
constexpr double AXIS_OUTLIER_MEDIANS = 2.5;
constexpr double AXIS_OUTLIER_FLOOR_M = 0.01;
constexpr std::size_t AXIS_MIN_KEPT = 3;
// Heights are scaled by at most this (m) in the fits' polynomials, for their conditioning.
constexpr double AXIS_MAX_SCALE_M = 1.0;

/// Radius range a slice circle may take and how far from the centreline its points may lie.
struct SliceBounds {
  double min_radius = MIN_TRUNK_RADIUS;
  double max_radius = MAX_TRUNK_RADIUS;
  double max_distance = 1e300;
};

/// A centreline refined on its slice circles and the slices about it.
struct SlicedAxis {
  Centerline line;
  std::vector<double> s, dist;  ///< each region point's arc length and distance from the line
  std::vector<Slice> slices;
};

/// The trunk's track: its axis and the radii it measured along it. A slice continues it: a
/// trunk tapers to a half or a third of its base radius, and one radius for the whole trunk
/// lets the thin top's slices take circles around the leader and a scaffold beside it.
class TrackedAxis {
 public:
  TrackedAxis() = default;  ///< no track: slices keep the trunk-wide bounds
  /// @param line the track's axis; radii: one per vertex of `axis`, or none (no track)
  TrackedAxis(Centerline line, const std::vector<Eigen::Vector3d>& axis,
              const std::vector<double>& radii)
      : line_(std::move(line)) {
    for (std::size_t i = 0; i < axis.size() && i < radii.size(); ++i)
      samples_.emplace_back(line_.project(axis[i]), radii[i]);
  }
  bool empty() const { return samples_.empty(); }
  /// The median of the track's radii within AXIS_RADIUS_WINDOW of the track point nearest p;
  /// 0 where there are none.
  double radiusNear(const Eigen::Vector3d& p) const {
    if (samples_.empty())
      return 0.0;
    const double s = line_.project(p);
    std::vector<double> r;
    for (const auto& [t, radius] : samples_) {
      if (std::abs(t - s) <= AXIS_RADIUS_WINDOW)
        r.push_back(radius);
    }
    return r.empty() ? 0.0 : median(r);
  }

 private:
  Centerline line_;
  std::vector<std::pair<double, double>> samples_;  // arc length on line_, radius
};

/// What bounds each slice's circle: its RANSAC band, the trunk-wide bounds, the track's local
/// radius where there is a track, and the radius each slice should continue (expectedRadii).
struct SliceLimits {
  double threshold = 0.0;  ///< RANSAC band (m)
  SliceBounds bounds;
  const TrackedAxis* track = nullptr;                    ///< none: the trunk-wide bounds
  const std::vector<double>* expected_radius = nullptr;  ///< per slice; none: no continuity
  double continuity = 0.0;     ///< share of the expected radius a RANSAC circle may differ by
  double surface_sigma = 0.0;  ///< noise the surface mode's kernel is for (m); 0: the band's
};

/// What fitting the trunk's segments needs: the region sliced along its refined centreline,
/// the trunk-wide bounds, the cylinders' RANSAC band and the noise their radii are corrected
/// for (TrunkModel::scatter).
struct SegmentContext {
  const Points& pts;
  const std::vector<int>& region;
  const SlicedAxis& axis;
  SliceBounds bounds;
  double cylinder_threshold = 0.0;
  double scatter = 0.0;
  const ModelerConfig& config;
};

/// Indices of the points within `window` (m) of `centre`.
std::vector<int> pointsWithin(const Points2& plane, const Eigen::Vector2d& centre, double window) {
  std::vector<int> out;
  for (std::size_t k = 0; k < plane.size(); ++k) {
    if ((plane[k] - centre).norm() < window)
      out.push_back(static_cast<int>(k));
  }
  return out;
}

/// The trimmed mean of a disc seen from all around, re-centred TRIMMED_MEAN_ROUNDS times from
/// `start`: its centre, and its points (indices into `plane`) within `window` (m) of the
/// centre before the last move.
Eigen::Vector2d trimmedMeanCentre(const Points2& plane, const Eigen::Vector2d& start, double window,
                                  std::vector<int>* inliers) {
  Eigen::Vector2d centre = start;
  for (int round = 0; round < TRIMMED_MEAN_ROUNDS; ++round) {
    *inliers = pointsWithin(plane, centre, window);
    if (inliers->empty())
      break;
    Eigen::Vector2d sum = Eigen::Vector2d::Zero();
    for (const int k : *inliers)
      sum += plane[k];
    centre = sum / static_cast<double>(inliers->size());
  }
  return centre;
}

}  // namespace

std::optional<SliceCircle> measureSliceCircle(const Points2& plane, const CircleRansacConfig& o,
                                              bool surface, double min_radius, double max_radius,
                                              double surface_sigma) {
  std::vector<int> inliers;
  auto circle = ransacCircle(plane, o, &inliers);
  if (!circle)
    return std::nullopt;
  if (sigmaOfBand(o.threshold) > NOISY_SLICE_SHARE * circle->radius) {
    // Noise comparable to the radius: the circle band covers the whole disc and its centre
    // drifts towards branch bases; the disc's trimmed mean is the better centre.
    std::vector<int> disc;
    circle->center = trimmedMeanCentre(plane, circle->center, circle->radius + o.threshold, &disc);
  }
  SliceCircle out{*circle, static_cast<int>(inliers.size()), false};
  if (surface) {
    // The surface under the branch bases: the mode of the distances from the centre.
    const double kernel = surface_sigma > 0.0 ? surface_sigma : sigmaOfBand(o.threshold);
    if (const auto mode = surfaceCircle(plane, *circle, kernel, min_radius, max_radius)) {
      out.circle = *mode;
      out.surface = true;
    }
  }
  return out;
}

namespace {

/// The points of each slice along the centreline within `max_distance` of it; `lo` is the
/// first slice's start (arc length, m).
std::vector<std::vector<int>> sliceMembers(const std::vector<int>& region, const SlicedAxis& axis,
                                           double height, double max_distance, double* lo) {
  double first = 1e300, last = -1e300;
  for (const double v : axis.s) {
    first = std::min(first, v);
    last = std::max(last, v);
  }
  first = std::max(first, -0.1);
  last = std::min(last, axis.line.length() + 0.1);
  const int count = std::max(1, static_cast<int>(std::ceil((last - first) / height)));
  std::vector<std::vector<int>> members(count);
  for (std::size_t k = 0; k < region.size(); ++k) {
    const int n = static_cast<int>(std::floor((axis.s[k] - first) / height));
    if (n >= 0 && n < count && axis.dist[k] <= max_distance)
      members[n].push_back(region[k]);
  }
  *lo = first;
  return members;
}

/// A slice circle's RANSAC options and the radius range its surface mode may take.
struct SliceCircleOptions {
  CircleRansacConfig ransac;
  double min_radius = 0.0, max_radius = 0.0;
};

/// The options of slice n, centred at `origin`: the trunk-wide bounds, or the track's local
/// radius where there is a track; RANSAC's radius within `continuity` of the expected radius.
SliceCircleOptions sliceCircleOptions(const SliceLimits& limits, int n,
                                      const Eigen::Vector3d& origin, const ModelerConfig& config) {
  SliceCircleOptions out;
  CircleRansacConfig& o = out.ransac;
  o.threshold = limits.threshold;
  o.iterations = config.fit.ransac_iterations;
  o.min_radius = limits.bounds.min_radius;
  o.max_radius = limits.bounds.max_radius;
  const double local_radius = limits.track ? limits.track->radiusNear(origin) : 0.0;
  if (local_radius > 0.0) {
    o.min_radius = std::max(MIN_TRUNK_RADIUS, SLICE_MIN_RADIUS_SHARE * local_radius);
    o.max_radius = std::min(MAX_TRUNK_RADIUS, SLICE_MAX_RADIUS_SHARE * local_radius);
    o.max_center_offset = SLICE_CENTRE_RADII * local_radius;
  }
  out.min_radius = o.min_radius;
  out.max_radius = o.max_radius;
  const std::vector<double>* expected = limits.expected_radius;
  if (expected && (*expected)[n] > 0.0) {
    o.min_radius = std::max(out.min_radius, (*expected)[n] * (1.0 - limits.continuity));
    o.max_radius = std::min(out.max_radius, (*expected)[n] * (1.0 + limits.continuity));
  }
  o.seed = config.seed * 7919 + static_cast<std::uint64_t>(n);
  return out;
}

/// Slice n's circle from its members. With calibrate_at (the range noise), its corrected
/// radius goes through the trunk calibration; without, it is the radius.
void measureSlice(const Points& pts, const std::vector<int>& members, const Centerline& line,
                  const SliceLimits& limits, int n, std::optional<double> calibrate_at,
                  const ModelerConfig& config, Slice& sl) {
  sl.points = static_cast<int>(members.size());
  if (sl.points < MIN_SLICE_POINTS) {
    sl.outliers = sl.points;
    sl.outlier_share = sl.points > 0 ? 1.0 : 0.0;
    return;
  }
  const double mid = sl.s0 + 0.5 * config.trunk.slice_height_m;
  const Eigen::Vector3d origin = line.pointAt(mid), dir = line.directionAt(mid);
  const Eigen::Vector3d u = dir.unitOrthogonal(), v = dir.cross(u);
  Points2 plane;
  for (const int i : members)
    plane.emplace_back((pts[i] - origin).dot(u), (pts[i] - origin).dot(v));
  const SliceCircleOptions o = sliceCircleOptions(limits, n, origin, config);
  const auto measured = measureSliceCircle(plane, o.ransac, config.noise.correct_bias, o.min_radius,
                                           o.max_radius, limits.surface_sigma);
  sl.outliers = sl.points - (measured ? measured->inliers : 0);
  sl.outlier_share = static_cast<double>(sl.outliers) / sl.points;
  if (!measured || measured->inliers < MIN_SLICE_POINTS / 2)
    return;
  sl.has_circle = true;
  sl.radius = measured->circle.radius;
  sl.center = origin + measured->circle.center.x() * u + measured->circle.center.y() * v;
  sl.corrected_radius = sl.radius;
  // The beam footprint's wings and the noise widen thin sections: the tables take them off.
  if (measured->surface && calibrate_at) {
    sl.corrected_radius =
        config.trunk_calibration.correct(sl.radius, *calibrate_at, MIN_TRUNK_RADIUS);
  }
}

/// RANSAC circles of every slice along the axis (trunk.slice_height_m apart).
std::vector<Slice> computeSlices(const Points& pts, const std::vector<int>& region,
                                 const SlicedAxis& axis, const SliceLimits& limits,
                                 std::optional<double> calibrate_at, const ModelerConfig& config) {
  const double height = config.trunk.slice_height_m;
  double lo = 0.0;
  const auto members = sliceMembers(region, axis, height, limits.bounds.max_distance, &lo);
  const int count = static_cast<int>(members.size());
  std::vector<Slice> slices(count);
  // Slices are independent (each RANSAC seeded by its index): all cores, same result.
  parallelFor(count, [&](int n) {
    slices[n].s0 = lo + n * height;
    measureSlice(pts, members[n], axis.line, limits, n, calibrate_at, config, slices[n]);
  });
  return slices;
}

/// The point at height z of x and y fitted as polynomials of `degree` in the height to the
/// centres, in AXIS_FIT_ROUNDS rounds that drop centres pulled aside (AXIS_OUTLIER_MEDIANS);
/// fewer centres than terms take a lower degree. Nothing without centres.
std::optional<Eigen::Vector3d> axisPointFit(std::vector<Eigen::Vector3d> centres, double z,
                                            int degree, double scale) {
  if (centres.empty())
    return std::nullopt;
  Eigen::Vector2d at = Eigen::Vector2d::Zero();
  for (int round = 0; round < AXIS_FIT_ROUNDS; ++round) {
    const int terms = std::clamp(static_cast<int>(centres.size()) - 1, 1, degree + 1);
    Eigen::MatrixXd A(centres.size(), terms);
    Eigen::MatrixXd xy(centres.size(), 2);
    for (std::size_t i = 0; i < centres.size(); ++i) {
      const double t = (centres[i].z() - z) / scale;
      for (int k = 0; k < terms; ++k)
        A(i, k) = std::pow(t, k);
      xy.row(i) = centres[i].head<2>().transpose();
    }
    const Eigen::MatrixXd coefficients = A.colPivHouseholderQr().solve(xy);
    at = coefficients.row(0).transpose();
    if (round + 1 == AXIS_FIT_ROUNDS)
      break;
    std::vector<double> off(centres.size());
    for (std::size_t i = 0; i < centres.size(); ++i)
      off[i] = (A.row(i) * coefficients - xy.row(i)).norm();
    const double limit = std::max(AXIS_OUTLIER_FLOOR_M, AXIS_OUTLIER_MEDIANS * median(off));
    std::vector<Eigen::Vector3d> kept;
    for (std::size_t i = 0; i < centres.size(); ++i) {
      if (off[i] <= limit)
        kept.push_back(centres[i]);
    }
    if (kept.size() < AXIS_MIN_KEPT || kept.size() == centres.size())
      break;
    centres.swap(kept);
  }
  if (!at.allFinite())
    return std::nullopt;
  return Eigen::Vector3d(at.x(), at.y(), z);
}

/// The axis point at height z under `smoothing`, from the centres in its window but the one at
/// index `left_out` (none: -1).
std::optional<Eigen::Vector3d> axisPointAt(const std::vector<Eigen::Vector3d>& centres, double z,
                                           const AxisSmoothing& smoothing, int left_out = -1) {
  std::vector<Eigen::Vector3d> window;
  for (std::size_t i = 0; i < centres.size(); ++i) {
    if (static_cast<int>(i) != left_out && std::abs(centres[i].z() - z) <= smoothing.half_window_m)
      window.push_back(centres[i]);
  }
  return axisPointFit(std::move(window), z, smoothing.degree,
                      std::min(smoothing.half_window_m, AXIS_MAX_SCALE_M));
}

/// The median distance (m) between each centre and the axis point `smoothing` predicts at its
/// height from the others; infinite when it predicts none.
double leaveOneOutMiss(const std::vector<Eigen::Vector3d>& centres,
                       const AxisSmoothing& smoothing) {
  std::vector<double> miss;
  for (std::size_t i = 0; i < centres.size(); ++i) {
    if (const auto p = axisPointAt(centres, centres[i].z(), smoothing, static_cast<int>(i)))
      miss.push_back((p->head<2>() - centres[i].head<2>()).norm());
  }
  return miss.empty() ? std::numeric_limits<double>::infinity() : median(miss);
}

/// The smoothing of AXIS_SMOOTHINGS the centres call for (AXIS_LOCAL_GAIN).
const AxisSmoothing& chooseSmoothing(const std::vector<Eigen::Vector3d>& centres) {
  const AxisSmoothing* chosen = std::begin(AXIS_SMOOTHINGS);
  double chosen_miss = leaveOneOutMiss(centres, *chosen);
  for (const AxisSmoothing* local = chosen + 1; local != std::end(AXIS_SMOOTHINGS); ++local) {
    const double miss = leaveOneOutMiss(centres, *local);
    if (chosen_miss > AXIS_MIN_MISS_M && miss < AXIS_LOCAL_GAIN * chosen_miss) {
      chosen = local;
      chosen_miss = miss;
    }
  }
  return *chosen;
}

/// A smooth trunk axis through noisy centres, sampled every `step` over their heights, with
/// the smoothing they call for (chooseSmoothing).
std::vector<Eigen::Vector3d> smoothAxis(const std::vector<Eigen::Vector3d>& centres, double step) {
  double z0 = std::numeric_limits<double>::infinity(), z1 = -z0;
  for (const auto& c : centres) {
    z0 = std::min(z0, c.z());
    z1 = std::max(z1, c.z());
  }
  if (centres.size() < 2 || z1 - z0 < 1e-6)
    return centres;
  const AxisSmoothing& smoothing = chooseSmoothing(centres);
  std::vector<Eigen::Vector3d> out;
  const int n = std::max(1, static_cast<int>(std::ceil((z1 - z0) / step)));
  for (int i = 0; i <= n; ++i) {
    if (const auto p = axisPointAt(centres, z0 + (z1 - z0) * i / n, smoothing))
      out.push_back(*p);
  }
  return out.size() >= 2 ? out : centres;
}

/// Running median of the slice radii over +/- 3 slices: the radius a slice should continue.

std::vector<double> expectedRadii(const std::vector<Slice>& slices) {
  std::vector<double> out(slices.size(), 0.0);
  for (std::size_t n = 0; n < slices.size(); ++n) {
    std::vector<double> r;
    for (std::size_t k = n >= 3 ? n - 3 : 0; k < std::min(slices.size(), n + 4); ++k) {
      if (slices[k].has_circle)
        r.push_back(slices[k].radius);
    }
    out[n] = median(r);
  }
  return out;
}

/// The centreline through the slice circles that sit near the current one.
Centerline refineCenterline(const std::vector<Slice>& slices, const Centerline& current,
                            double radius, double step) {
  std::vector<Eigen::Vector3d> centres;
  for (const auto& sl : slices) {
    double d = 0.0;
    current.project(sl.center, &d);
    if (sl.has_circle && d < radius)
      centres.push_back(sl.center);
  }
  if (centres.size() < 4)
    return current;
  return Centerline(smoothAxis(centres, step));
}

/// Whether region point k lies in the segment [a, b) (arc length, m) within the trunk's reach.
bool inSegment(const SegmentContext& c, std::size_t k, double a, double b) {
  return c.axis.s[k] >= a && c.axis.s[k] < b && c.axis.dist[k] <= c.bounds.max_distance;
}

/// The region's points of the segment [a, b).
Points segmentPoints(const SegmentContext& c, double a, double b) {
  Points sub;
  for (std::size_t k = 0; k < c.region.size(); ++k) {
    if (inSegment(c, k, a, b))
      sub.push_back(c.pts[c.region[k]]);
  }
  return sub;
}

/// The RANSAC cylinder of the segment [a, b]: within the trunk-wide bounds, and with
/// fit.constrain within radius_continuity of its slices' median radius, its axis within 10 deg
/// of the centreline's chord and within max_tilt_deg of vertical. With noise.correct_bias its
/// radius is the median of its slices' corrected radii. `stream` seeds its RANSAC.
std::optional<Cylinder> fitSegment(const SegmentContext& c, double a, double b,
                                   std::uint64_t stream) {
  const ModelerConfig& config = c.config;
  const Points sub = segmentPoints(c, a, b);
  if (sub.size() < static_cast<std::size_t>(MIN_SLICE_POINTS))
    return std::nullopt;
  Eigen::Vector3d axis = (c.axis.line.pointAt(b) - c.axis.line.pointAt(a)).normalized();
  if (!axis.allFinite())
    axis = Eigen::Vector3d::UnitZ();
  CylinderRansacConfig o;
  o.threshold = c.cylinder_threshold;
  o.circle_iterations = config.fit.ransac_iterations;
  o.seed = config.seed * 104729 + stream;
  o.min_radius = c.bounds.min_radius;
  o.max_radius = c.bounds.max_radius;
  o.max_axis_deviation = 35.0 * DEG;
  if (config.fit.constrain) {
    std::vector<double> r;
    for (const auto& sl : c.axis.slices) {
      if (sl.has_circle && sl.s0 + 1e-9 >= a - 0.5 * config.trunk.slice_height_m && sl.s0 < b)
        r.push_back(sl.radius);
    }
    const double expected = median(r);
    if (expected > 0.0) {
      o.min_radius = std::max(MIN_TRUNK_RADIUS, expected * (1.0 - config.trunk.radius_continuity));
      o.max_radius = expected * (1.0 + config.trunk.radius_continuity);
    }
    o.max_axis_deviation = 10.0 * DEG;
  }
  std::vector<int> inliers;
  auto cyl = ransacCylinder(sub, axis, o, &inliers);
  if (!cyl)
    return std::nullopt;
  if (config.fit.constrain &&
      std::acos(std::clamp(cyl->axis.z(), -1.0, 1.0)) > config.trunk.max_tilt_deg * DEG) {
    return std::nullopt;
  }
  if (cyl->axis.z() < 0.0)
    cyl->axis = -cyl->axis;
  if (config.noise.correct_bias) {
    // Median over the segment's slices of their noise-corrected radii: slices at branch
    // junctions, whose points include the branch's base, are the minority.
    std::vector<double> r;
    for (const auto& sl : c.axis.slices) {
      if (sl.has_circle && sl.s0 + 0.5 * config.trunk.slice_height_m >= a &&
          sl.s0 + 0.5 * config.trunk.slice_height_m < b) {
        r.push_back(sl.corrected_radius);
      }
    }
    if (r.empty()) {
      Points in;
      for (const int i : inliers)
        in.push_back(sub[i]);
      cyl->radius =
          noiseCorrectedRadius(*cyl, in, c.scatter, c.cylinder_threshold, MIN_TRUNK_RADIUS);
    } else {
      cyl->radius = std::max(MIN_TRUNK_RADIUS, median(r));
    }
  }
  return cyl;
}

/// A segment from its slices alone: axis the centreline's chord over [a, b], radius the median
/// of the slices' corrected radii there; nothing when fewer than two slices have a circle.
std::optional<Cylinder> segmentFromSlices(const std::vector<Slice>& slices, const Centerline& line,
                                          double a, double b, double slice_height) {
  std::vector<double> r;
  for (const auto& sl : slices) {
    const double mid = sl.s0 + 0.5 * slice_height;
    if (sl.has_circle && mid >= a && mid < b)
      r.push_back(sl.corrected_radius);
  }
  if (r.size() < 2)
    return std::nullopt;
  Cylinder c;
  const Eigen::Vector3d p0 = line.pointAt(a), p1 = line.pointAt(b);
  c.axis = (p1 - p0).normalized();
  if (!c.axis.allFinite())
    return std::nullopt;
  if (c.axis.z() < 0.0)
    c.axis = -c.axis;
  c.center = 0.5 * (p0 + p1);
  c.length = (p1 - p0).norm();
  c.radius = std::max(MIN_TRUNK_RADIUS, median(r));
  return c;
}

}  // namespace

double TrunkModel::baseZ() const {
  double z = std::numeric_limits<double>::infinity();
  for (const auto& c : cylinders)
    z = std::min(z, (c.center - 0.5 * c.length * c.axis).z());
  return z;
}

int TrunkModel::cylinderAt(double s) const {
  int best = -1;
  double best_gap = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < cylinder_ranges.size(); ++i) {
    const auto [a, b] = cylinder_ranges[i];
    const double gap = s < a ? a - s : (s > b ? s - b : 0.0);
    if (gap < best_gap) {
      best_gap = gap;
      best = static_cast<int>(i);
    }
  }
  return best;
}

double TrunkModel::diameterAt(double s) const {
  const auto middle = [&](std::size_t i) {
    return 0.5 * (cylinder_ranges[i].first + cylinder_ranges[i].second);
  };
  const std::size_t n = cylinder_ranges.size();
  if (n == 0)
    return 0.0;
  if (s <= middle(0))
    return 2.0 * cylinders.front().radius;
  for (std::size_t i = 0; i + 1 < n; ++i) {
    if (s <= middle(i + 1)) {
      const double f = (s - middle(i)) / std::max(middle(i + 1) - middle(i), 1e-9);
      return 2.0 * ((1.0 - f) * cylinders[i].radius + f * cylinders[i + 1].radius);
    }
  }
  return 2.0 * cylinders.back().radius;
}

namespace {

/// A track's slice circle when the noise is comparable to the trunk's radius and a RANSAC band
/// would cover the whole disc (relative to the predicted centre, the origin). The centre is
/// the disc's trimmed mean, unless a robust circle fit from the prediction, possible while the
/// band leaves a hole inside the ring, lies more than RING_DISAGREEMENT_SIGMAS away: then
/// something beside the trunk pulls the mean (a branch leaving at a whorl fills one side of
/// the disc, and a track following the mean turns onto the branch), and the ring, which only
/// the points on it pull, is the centre. The radius is the second moment
/// about the centre, r^2 + sigma^2.
std::optional<Circle> noisySliceCircle(const Points2& plane, double r, double sigma,
                                       const CircleRansacConfig& o, std::vector<int>* inliers) {
  const double window = r + noiseBand(sigma);
  Eigen::Vector2d centre = trimmedMeanCentre(plane, Eigen::Vector2d::Zero(), window, inliers);
  if (noiseBand(sigma) < r) {
    const auto ring = robustCircle(plane, Circle{Eigen::Vector2d::Zero(), r}, noiseBand(sigma));
    if (ring && ring->radius >= o.min_radius && ring->radius <= o.max_radius &&
        ring->center.norm() < r &&
        (ring->center - centre).norm() > RING_DISAGREEMENT_SIGMAS * sigma) {
      centre = ring->center;
      *inliers = pointsWithin(plane, centre, window);
    }
  }
  if (inliers->empty())
    return std::nullopt;
  double m2 = 0.0;
  for (const int k : *inliers)
    m2 += (plane[k] - centre).squaredNorm();
  const double est = std::sqrt(std::max(0.0, m2 / inliers->size() - sigma * sigma));
  return Circle{centre, std::clamp(est, o.min_radius, o.max_radius)};
}

}  // namespace

// One climb up the trunk, circle by circle; the state carried between steps (last circle,
// step, misses) is what keeps it one loop.
TrackedTrunk trackTrunk(const Points& pts, const PointIndex& index, const Eigen::Vector3d& start,
                        const Eigen::Vector3d& direction, double radius, double threshold,
                        const ModelerConfig& config, int max_misses, bool trust_radius) {
  TrackedTrunk out;
  const double h = config.trunk.slice_height_m;
  Eigen::Vector3d c = start, t = direction.normalized();
  double r = std::clamp(radius, MIN_TRUNK_RADIUS, MAX_TRUNK_RADIUS);
  int misses = 0;
  std::uint64_t stream = 0;
  for (int step = 0; step < 400 && misses < max_misses; ++step) {
    const Eigen::Vector3d predicted = c + h * t;
    // Until the first circle is found the start's radius is only a guess (a cluster's fit
    // to an arc of a thick trunk can be half its size): search wide, any trunk radius.
    const bool first = out.centers.empty() && !trust_radius;
    const double lateral = first ? std::max(FIRST_WINDOW, TRUNK_REACH_RADII * r) : trunkReach(r);
    const Eigen::Vector3d u = t.unitOrthogonal(), v = t.cross(u);
    Points2 plane;
    for (const int i : index.within(predicted, std::hypot(0.5 * h, lateral))) {
      const Eigen::Vector3d w = pts[i] - predicted;
      if (std::abs(w.dot(t)) <= 0.5 * h)
        plane.emplace_back(w.dot(u), w.dot(v));
    }
    CircleRansacConfig o;
    o.threshold = threshold;
    o.iterations = config.fit.ransac_iterations;
    o.min_radius = first ? MIN_TRUNK_RADIUS : std::max(MIN_TRUNK_RADIUS, 0.6 * r);
    o.max_radius =
        first ? std::max(1.25 * r, 0.5 * FIRST_WINDOW) : (out.centers.empty() ? 1.6 : 1.25) * r;
    o.seed = config.seed * 31337 + stream++;
    std::vector<int> inliers;
    std::optional<Circle> circle;
    const double sigma = sigmaOfBand(threshold);
    if (plane.size() < MIN_SLICE_POINTS) {
      // nothing to fit
    } else if (first || sigma < NOISY_SLICE_SHARE * r) {
      // The first circle is RANSAC's whatever the guess: the disc below needs the radius, and
      // a small guess (a fragment's arc fit) would settle on a patch of the trunk's flank.
      circle = ransacCircle(plane, o, &inliers);
    } else {
      circle = noisySliceCircle(plane, r, sigma, o, &inliers);
    }

    const bool ok = circle && inliers.size() >= MIN_SLICE_POINTS / 2 &&
                    circle->center.norm() < (first ? lateral : r + 0.02);
    if (!ok) {
      ++misses;
      c = predicted;
      continue;
    }
    misses = 0;
    const Eigen::Vector3d centre = predicted + circle->center.x() * u + circle->center.y() * v;
    if (!out.centers.empty()) {
      const Eigen::Vector3d step_dir = (centre - out.centers.back()).normalized();
      // Smooth the direction: one slice's centre is noisy, the trunk bends slowly.
      if (step_dir.allFinite() && step_dir.dot(t) > 0.5)
        t = (0.7 * t + 0.3 * step_dir).normalized();
    }
    // The first circle was searched with any trunk radius: it replaces the start's guess
    // (blending a cluster's arc-fit radius in would cap the next circles below the trunk's).
    r = first ? circle->radius : 0.7 * r + 0.3 * circle->radius;
    c = centre;
    out.centers.push_back(centre);
    out.radii.push_back(circle->radius);
  }
  return out;
}

namespace {

/// The line through the RESUME_LINE_SLICES circles beneath a track's first `kept` circles.
struct LineBeneath {
  Eigen::Vector3d point;  ///< the circles' mean
  Eigen::Vector3d axis;   ///< unit, upwards along the track
  double radius = 0.0;    ///< the circles' median radius
  /// @brief The line's point level (along the axis) with p.
  Eigen::Vector3d levelWith(const Eigen::Vector3d& p) const {
    return point + (p - point).dot(axis) * axis;
  }
};

LineBeneath lineBeneath(const TrackedTrunk& track, std::size_t kept) {
  const std::size_t first = kept - RESUME_LINE_SLICES;
  const Points below(track.centers.begin() + first, track.centers.begin() + kept);
  LineBeneath line;
  line.axis = principalAxis(below, &line.point);
  if (line.axis.dot(below.back() - below.front()) < 0.0)
    line.axis = -line.axis;
  line.radius =
      median(std::vector<double>(track.radii.begin() + first, track.radii.begin() + kept));
  return line;
}

/// The track's first `kept` circles followed by `more`'s.
TrackedTrunk joinedAt(const TrackedTrunk& track, std::size_t kept, const TrackedTrunk& more) {
  TrackedTrunk joined;
  joined.centers.assign(track.centers.begin(), track.centers.begin() + kept);
  joined.radii.assign(track.radii.begin(), track.radii.begin() + kept);
  joined.centers.insert(joined.centers.end(), more.centers.begin(), more.centers.end());
  joined.radii.insert(joined.radii.end(), more.radii.begin(), more.radii.end());
  return joined;
}

/// The track's first `kept` circles joined with a climb from `from` along the line beneath
/// them; nothing when that climb ends within a slice of the track's end.
std::optional<TrackedTrunk> climbOnFrom(const Points& pts, const PointIndex& index,
                                        const TrackedTrunk& track, std::size_t kept,
                                        const LineBeneath& line, const Eigen::Vector3d& from,
                                        double threshold, const ModelerConfig& config) {
  TrackedTrunk more = trackTrunk(pts, index, from, line.axis, line.radius, threshold, config,
                                 TRACK_MAX_MISSES, true);
  if (more.centers.empty() ||
      (more.centers.back() - track.centers.back()).dot(line.axis) <= config.trunk.slice_height_m)
    return std::nullopt;
  return joinedAt(track, kept, more);
}

/// Whether the track's end lies off the line beneath its first `kept` circles: it was pulled
/// or turned aside there (a track that ran out of trunk ends on its line).
bool endsOffTheLine(const TrackedTrunk& track, const LineBeneath& line) {
  const Eigen::Vector3d& end = track.centers.back();
  return (end - line.levelWith(end)).norm() > RESUME_PULL_RADII * line.radius;
}

/// The track resumed past its last RESUME_BACKOFF_SLICES circles along the line beneath them,
/// above its end, when that climbs more than a slice beyond its end; nothing otherwise.
std::optional<TrackedTrunk> resumePastPull(const Points& pts, const PointIndex& index,
                                           const TrackedTrunk& track, double threshold,
                                           const ModelerConfig& config) {
  const std::size_t n = track.centers.size();
  if (n < static_cast<std::size_t>(RESUME_BACKOFF_SLICES + RESUME_LINE_SLICES))
    return std::nullopt;
  const std::size_t kept = n - RESUME_BACKOFF_SLICES;
  const LineBeneath line = lineBeneath(track, kept);
  if (!endsOffTheLine(track, line))
    return std::nullopt;
  // From the line's point level with the track's end: the pulled slices are not fitted again.
  return climbOnFrom(pts, index, track, kept, line, line.levelWith(track.centers.back()), threshold,
                     config);
}

/// Whether the circles from `kept` on are, by their median, no thicker than the line beneath
/// them allows (TAPER_SWELL): the leader above a fork is not thicker than the trunk below it,
/// whereas circles around the forks of a crown are.
bool narrowerAbove(const TrackedTrunk& track, std::size_t kept, const LineBeneath& line) {
  const double above = median(std::vector<double>(track.radii.begin() + kept, track.radii.end()));
  return above <= (1.0 + TAPER_SWELL) * line.radius;
}

/// The track resumed on the leader past a fork where it took a branch: for each circle up to
/// FORK_MAX_BACKOFF_M below its end off whose line beneath the track ends, a climb along that
/// line from FORK_SKIP_M above it; of those that hold more circles than they drop and are
/// narrower above, the one that climbs highest. Nothing when none does.
std::optional<TrackedTrunk> resumePastFork(const Points& pts, const PointIndex& index,
                                           const TrackedTrunk& track, double threshold,
                                           const ModelerConfig& config) {
  const double h = config.trunk.slice_height_m;
  const int n = static_cast<int>(track.centers.size());
  const int max_backoff =
      std::min(n - RESUME_LINE_SLICES, static_cast<int>(std::lround(FORK_MAX_BACKOFF_M / h)));
  std::optional<TrackedTrunk> best;
  for (int backoff = RESUME_BACKOFF_SLICES + 1; backoff <= max_backoff; ++backoff) {
    const std::size_t kept = n - backoff;
    const LineBeneath line = lineBeneath(track, kept);
    if (!endsOffTheLine(track, line))
      continue;
    const Eigen::Vector3d from = line.levelWith(track.centers[kept - 1]) + FORK_SKIP_M * line.axis;
    auto resumed = climbOnFrom(pts, index, track, kept, line, from, threshold, config);
    if (resumed && resumed->centers.size() > track.centers.size() &&
        narrowerAbove(*resumed, kept, line) &&
        (!best || resumed->centers.back().z() > best->centers.back().z()))
      best = std::move(resumed);
  }
  return best;
}

}  // namespace

namespace {

/// The track resumed past whorls, and with `past_forks` past forks when no whorl pulled it,
/// up to MAX_RESUMES times.
TrackedTrunk resumeRepeatedly(const Points& pts, const PointIndex& index, TrackedTrunk track,
                              double threshold, const ModelerConfig& config, bool past_forks) {
  for (int k = 0; k < MAX_RESUMES; ++k) {
    auto resumed = resumePastPull(pts, index, track, threshold, config);
    if (!resumed && past_forks)
      resumed = resumePastFork(pts, index, track, threshold, config);
    if (!resumed)
      break;
    track = std::move(*resumed);
  }
  return track;
}

}  // namespace

TrackedTrunk resumePastWhorls(const Points& pts, const PointIndex& index, TrackedTrunk track,
                              double threshold, const ModelerConfig& config) {
  return resumeRepeatedly(pts, index, std::move(track), threshold, config, false);
}

TrackedTrunk resumePastWhorlsAndForks(const Points& pts, const PointIndex& index,
                                      TrackedTrunk track, double threshold,
                                      const ModelerConfig& config) {
  return resumeRepeatedly(pts, index, std::move(track), threshold, config, true);
}

std::optional<TrackedTrunk> climbAgainFrom(const Points& pts, const PointIndex& index,
                                           const TrackedTrunk& track, std::size_t kept,
                                           double threshold, const ModelerConfig& config) {
  if (kept < static_cast<std::size_t>(RESUME_LINE_SLICES) || kept > track.centers.size())
    return std::nullopt;
  const LineBeneath line = lineBeneath(track, kept);
  const TrackedTrunk more =
      trackTrunk(pts, index, line.levelWith(track.centers[kept - 1]), line.axis, line.radius,
                 threshold, config, TRACK_MAX_MISSES, true);
  if (more.centers.empty())
    return std::nullopt;
  return resumePastWhorlsAndForks(pts, index, joinedAt(track, kept, more), threshold, config);
}

double estimateNoiseSigma(const Points& pts, const Centerline& line,
                          const std::vector<Slice>& slices, double slice_height,
                          std::vector<double>* slice_radii) {
  std::vector<double> residuals, radii;
  for (const auto& sl : slices) {
    if (!sl.has_circle || sl.radius < 0.02)
      continue;
    const Eigen::Vector3d dir = line.directionAt(sl.s0 + 0.5 * slice_height);
    for (const auto& p : pts) {
      const Eigen::Vector3d w = p - sl.center;
      const double along = w.dot(dir);
      if (std::abs(along) > 0.5 * slice_height)
        continue;
      const double d = (w - along * dir).norm() - sl.radius;
      if (std::abs(d) < 0.5 * sl.radius) {
        residuals.push_back(d);
        radii.push_back(sl.radius);
      }
    }
  }
  if (residuals.size() < 200)
    return -1.0;
  if (slice_radii) {
    // The quartiles of the residuals' slice radii stand for the slices.
    std::sort(radii.begin(), radii.end());
    *slice_radii = {radii[radii.size() / 4], radii[radii.size() / 2], radii[3 * radii.size() / 4]};
  }
  return noiseFromRadialResiduals(std::move(residuals));
}

std::vector<double> disturbancePartitions(const std::vector<Slice>& slices, double slice_height,
                                          int zero_run, double top) {
  std::vector<double> cuts{slices.empty() ? 0.0 : std::max(0.0, slices.front().s0)};
  int flat = 0;
  for (std::size_t n = 1; n < slices.size(); ++n) {
    const double d = slices[n].outlier_share - slices[n - 1].outlier_share;
    if (d > ZERO_SLOPE && flat >= zero_run) {
      const double s = slices[n].s0;
      if (s - cuts.back() > slice_height * 0.99)
        cuts.push_back(s);
    }
    flat = std::abs(d) <= ZERO_SLOPE ? flat + 1 : 0;
  }
  if (top - cuts.back() > 1e-9)
    cuts.push_back(top);
  return cuts;
}

namespace {

// Cuts where the centreline bends: a stretch whose centreline leaves the chord between its
// ends by more than max_bend is split where it leaves it most, recursively (a polyline
// simplification of the centreline, at slice resolution).
void splitAtBends(const Centerline& line, double a, double b, double step, double max_bend,
                  double min_length, std::vector<double>& cuts) {
  if (max_bend <= 0.0 || b - a < 2.0 * min_length)
    return;
  const Eigen::Vector3d p = line.pointAt(a), q = line.pointAt(b);
  const Eigen::Vector3d chord = (q - p).normalized();
  double worst = 0.0, at = a;
  for (double t = a + min_length; t <= b - min_length + 1e-9; t += step) {
    const Eigen::Vector3d d = line.pointAt(t) - p;
    const double off = (d - d.dot(chord) * chord).norm();
    if (off > worst) {
      worst = off;
      at = t;
    }
  }
  if (worst <= max_bend)
    return;
  splitAtBends(line, a, at, step, max_bend, min_length, cuts);
  cuts.push_back(at);
  splitAtBends(line, at, b, step, max_bend, min_length, cuts);
}

/// Cuts with the segments shorter than min_length (m) joined to their upper neighbour (the
/// last to its lower one): a cylinder needs some length to be measured.
std::vector<double> joinShortSegments(const std::vector<double>& cuts, double min_length) {
  std::vector<double> merged{cuts.front()};
  for (std::size_t i = 1; i < cuts.size(); ++i) {
    if (cuts[i] - merged.back() >= min_length || i + 1 == cuts.size())
      merged.push_back(cuts[i]);
  }
  if (merged.size() >= 3 && merged.back() - merged[merged.size() - 2] < min_length)
    merged.erase(merged.end() - 2);
  return merged;
}

/// Where the share of the segment [a, b)'s points on its cylinder jumps most between bins of
/// about a slice, if by more than curvature_jump and with min_segment_length on either side.
std::optional<double> curvatureCut(const SegmentContext& c, const Cylinder& cyl, double a,
                                   double b) {
  const ModelerConfig& config = c.config;
  const std::vector<double>& s = c.axis.s;
  const int bins = std::max(2, static_cast<int>((b - a) / config.trunk.slice_height_m));
  std::vector<int> in(bins, 0), all(bins, 0);
  for (std::size_t k = 0; k < c.region.size(); ++k) {
    if (!inSegment(c, k, a, b))
      continue;
    const int bin = std::min(bins - 1, static_cast<int>((s[k] - a) / (b - a) * bins));
    ++all[bin];
    in[bin] += std::abs(axisDistance(cyl, c.pts[c.region[k]]) - cyl.radius) < c.cylinder_threshold;
  }
  double jump = 0.0;
  int at = -1;
  for (int k = 1; k < bins; ++k) {
    if (all[k] < MIN_SLICE_POINTS || all[k - 1] < MIN_SLICE_POINTS)
      continue;
    const double j =
        std::abs(static_cast<double>(in[k]) / all[k] - static_cast<double>(in[k - 1]) / all[k - 1]);
    const double cut = a + (b - a) * k / bins;
    if (j > jump && cut - a >= config.trunk.min_segment_length_m &&
        b - cut >= config.trunk.min_segment_length_m) {
      jump = j;
      at = k;
    }
  }
  if (at > 0 && jump > config.trunk.curvature_jump)
    return a + (b - a) * at / bins;
  return std::nullopt;
}

/// Curvature: a segment (at least twice min_segment_length) whose outliers jump along its
/// cylinder is split at the jump.
std::vector<double> splitAtCurvature(const SegmentContext& c, const std::vector<double>& cuts) {
  std::vector<double> out{cuts.front()};
  std::uint64_t stream = 0;
  for (std::size_t i = 1; i < cuts.size(); ++i) {
    const double a = out.back(), b = cuts[i];
    if (b - a >= 2.0 * c.config.trunk.min_segment_length_m) {
      if (const auto cyl = fitSegment(c, a, b, stream++)) {
        if (const auto cut = curvatureCut(c, *cyl, a, b))
          out.push_back(*cut);
      }
    }
    out.push_back(b);
  }
  return out;
}

/// Each segment longer than max_length (m) cut into equal parts no longer than it.
std::vector<double> splitLongSegments(const std::vector<double>& cuts, double max_length) {
  std::vector<double> out{cuts.front()};
  for (std::size_t i = 1; i < cuts.size(); ++i) {
    const double a = out.back(), b = cuts[i];
    const int parts = static_cast<int>(std::ceil((b - a) / max_length - 1e-9));
    for (int k = 1; k < parts; ++k)
      out.push_back(a + (b - a) * k / parts);
    out.push_back(b);
  }
  return out;
}

/// A trunk tapers: a segment measured thicker than the one below it by more than a swelling at
/// a whorl (TAPER_SWELL) has circles through branch bases or noise wider than its radius (the
/// thin top at high noise); the segment below bounds it.
void boundByTheSegmentBelow(std::vector<Cylinder>& cylinders) {
  for (std::size_t i = 1; i < cylinders.size(); ++i)
    cylinders[i].radius =
        std::min(cylinders[i].radius, cylinders[i - 1].radius * (1.0 + TAPER_SWELL));
}

}  // namespace

namespace {

// Rounds of centreline refinement on the initial axis, and the least radius they assume.
constexpr int CENTERLINE_ROUNDS = 2;
constexpr double CENTERLINE_MIN_RADIUS = 0.02;     // m
constexpr std::uint64_t SEGMENT_SEED_BASE = 1000;  // + the segment's index

/// Each region point's position along the centreline and distance from it, on all cores.
void projectRegion(const Points& pts, const std::vector<int>& region, const Centerline& line,
                   std::vector<double>& s, std::vector<double>& dist) {
  parallelFor(static_cast<int>(region.size()),
              [&](int k) { s[k] = line.project(pts[region[k]], &dist[k]); });
}

SliceBounds sliceBounds(double initial_radius) {
  SliceBounds bounds;
  if (initial_radius > 0.0) {
    bounds.min_radius = std::max(MIN_TRUNK_RADIUS, SLICE_MIN_RADIUS_SHARE * initial_radius);
    bounds.max_radius = std::min(MAX_TRUNK_RADIUS, SLICE_MAX_RADIUS_SHARE * initial_radius);
    bounds.max_distance = trunkReach(initial_radius);
  }
  return bounds;
}

/// The slices whose circle keeps within NOISE_TRACK_RADII of the track's local radius (with
/// those that have no circle, which the estimate skips); all of them without a track.
std::vector<Slice> slicesOnTrack(const std::vector<Slice>& slices, const TrackedAxis& track) {
  if (track.empty())
    return slices;
  std::vector<Slice> out;
  for (const auto& sl : slices) {
    const double local = track.radiusNear(sl.center);
    if (!sl.has_circle || local <= 0.0 || sl.radius <= NOISE_TRACK_RADII * local)
      out.push_back(sl);
  }
  return out;
}

/// The region's two noise readings (TrunkModel::noise_sigma, search_sigma), m.
struct TrunkNoise {
  double range = 0.0;               ///< on the slices that keep to the track
  double search = 0.0;              ///< over every slice
  std::vector<double> slice_radii;  ///< standing for the slices `range` was read on
};

/// The region's noise: the configured one, or estimated from the slices; read once over every
/// slice and again on those on the track when some were left out.
TrunkNoise trunkNoise(const Points& pts, const std::vector<int>& region, const Centerline& line,
                      const std::vector<Slice>& slices, const TrackedAxis& track,
                      const ModelerConfig& config) {
  TrunkNoise n;
  if (config.noise.sigma_m >= 0.0) {
    n.range = n.search = config.noise.sigma_m;
    return n;
  }
  Points region_pts;
  for (const int i : region)
    region_pts.push_back(pts[i]);
  const double h = config.trunk.slice_height_m;
  const std::vector<Slice> on_track = slicesOnTrack(slices, track);
  n.search = std::max(
      0.0, estimateNoiseSigma(region_pts, line, slices, h,
                              on_track.size() == slices.size() ? &n.slice_radii : nullptr));
  n.range = on_track.size() == slices.size()
                ? n.search
                : std::max(0.0, estimateNoiseSigma(region_pts, line, on_track, h, &n.slice_radii));
  return n;
}

/// The segment boundaries along the centreline: disturbance partitions, short ones joined,
/// split at curvature, at bends (trunk.max_bend_m) and where too long.
std::vector<double> trunkCuts(const SegmentContext& c) {
  const ModelerConfig& config = c.config;
  const std::vector<Slice>& slices = c.axis.slices;
  const double h = config.trunk.slice_height_m;
  double top = 0.0;
  for (const auto& sl : slices) {
    if (sl.points >= MIN_SLICE_POINTS)
      top = std::max(top, sl.s0 + h);
  }
  const auto joined =
      joinShortSegments(disturbancePartitions(slices, h, config.trunk.disturbance_zero_run, top),
                        config.trunk.min_segment_length_m);
  std::vector<double> cuts = splitAtCurvature(c, joined);
  if (config.trunk.max_bend_m > 0.0) {
    std::vector<double> straight{cuts.front()};
    for (std::size_t i = 1; i < cuts.size(); ++i) {
      splitAtBends(c.axis.line, straight.back(), cuts[i], h, config.trunk.max_bend_m,
                   config.trunk.min_segment_length_m, straight);
      straight.push_back(cuts[i]);
    }
    cuts = std::move(straight);
  }
  if (config.trunk.max_segment_length_m > 0.0)
    cuts = splitLongSegments(cuts, config.trunk.max_segment_length_m);
  return cuts;
}

/// One cylinder per segment; with graph.follow_diameter a segment no RANSAC cylinder fits (a
/// whorl of branches, a bend) takes the centreline's chord and the slices' median radius,
/// rather than leaving a gap in the trunk that would orphan the branches on it.
void fitCylinders(const SegmentContext& c, TrunkModel& trunk) {
  const std::vector<double>& cuts = trunk.partitions;
  for (std::size_t i = 0; i + 1 < cuts.size(); ++i) {
    const double a = cuts[i], b = cuts[i + 1];
    if (auto cyl = fitSegment(c, a, b, SEGMENT_SEED_BASE + i)) {
      trunk.cylinders.push_back(*cyl);
      trunk.cylinder_ranges.emplace_back(a, b);
    } else if (c.config.graph.follow_diameter) {
      if (auto chord =
              segmentFromSlices(c.axis.slices, c.axis.line, a, b, c.config.trunk.slice_height_m)) {
        trunk.cylinders.push_back(*chord);
        trunk.cylinder_ranges.emplace_back(a, b);
      }
    }
  }
}

/// The cylinders' radii from a taper profile fitted to the slices, when one fits.
void applyTaperProfile(TrunkModel& trunk, const ModelerConfig& config) {
  const auto profile =
      TaperProfile::fit(trunk.slices, config.trunk.slice_height_m, TAPER_BELOW,
                        trunk.search_sigma >= TAPER_NOISY_SIGMA ? TAPER_ABOVE_NOISY : TAPER_ABOVE);
  if (!profile)
    return;
  for (std::size_t i = 0; i < trunk.cylinders.size(); ++i) {
    const auto& [a, b] = trunk.cylinder_ranges[i];
    trunk.cylinders[i].radius = std::max(MIN_TRUNK_RADIUS, profile->mean(a, b));
  }
}

/// Drops the trunk's top cylinders while the highest holds on its surface less than
/// MIN_TRUNK_SURFACE_SHARE of the returns in its stretch: there the trunk has run out.
void endWhereTheSurfaceEnds(const Points& pts, const std::vector<int>& region,
                            const ModelerConfig& config, TrunkModel& trunk) {
  const TrunkMembership m = trunkMembership(pts, region, trunk, trunkSurfaceBand(trunk, config));
  std::size_t kept = trunk.cylinders.size();
  while (kept > 1 && static_cast<double>(m.inliers[kept - 1]) <
                         MIN_TRUNK_SURFACE_SHARE * static_cast<double>(m.points[kept - 1]))
    --kept;
  if (kept == trunk.cylinders.size())
    return;
  trunk.cylinders.resize(kept);
  trunk.cylinder_ranges.resize(kept);
  const double top = trunk.cylinder_ranges.back().second;
  while (trunk.partitions.size() > 1 && trunk.partitions.back() > top + 1e-9)
    trunk.partitions.pop_back();
  if (trunk.partitions.back() < top - 1e-9)
    trunk.partitions.push_back(top);
}

/// Slices along a given centreline.
SlicedAxis slicesAlong(const Points& pts, const std::vector<int>& region, const Centerline& line,
                       const SliceBounds& bounds, const TrackedAxis& track,
                       const ModelerConfig& config) {
  SlicedAxis out{line, std::vector<double>(region.size()), std::vector<double>(region.size()), {}};
  projectRegion(pts, region, out.line, out.s, out.dist);
  out.slices =
      computeSlices(pts, region, out, SliceLimits{config.fit.circle_threshold_m, bounds, &track},
                    std::nullopt, config);
  return out;
}

/// Slices on the initial axis, then CENTERLINE_ROUNDS rounds of refining the centreline on
/// their circles and slicing again.
SlicedAxis refinedSlices(const Points& pts, const std::vector<int>& region,
                         const Centerline& initial, const SliceBounds& bounds,
                         const TrackedAxis& track, double initial_radius,
                         const ModelerConfig& config) {
  const double h = config.trunk.slice_height_m;
  SlicedAxis out = slicesAlong(pts, region, initial, bounds, track, config);
  for (int round = 1; round <= CENTERLINE_ROUNDS; ++round) {
    const Centerline refined =
        refineCenterline(out.slices, out.line, std::max(initial_radius, CENTERLINE_MIN_RADIUS), h);
    out = slicesAlong(pts, region, refined, bounds, track, config);
  }
  return out;
}

/// The noise a slice's surface mode reads its returns with (surfaceCircle's kernel): the one
/// its band stands for on the range noise alone, at the trunk's table reading. The band itself
/// keeps the search's scatter, which picks a circle among clutter; a kernel that wide took a
/// thin trunk's footprint wings and branch bases into its mode, where a rig's pipe (whose
/// scatter is its range noise) and the noise model (noise_bias.cpp) read with the narrower one.
double surfaceKernelSigma(double table_sigma, const ModelerConfig& config) {
  if (!config.noise.derive_parameters)
    return 0.0;
  return std::max(sigmaOfBand(config.fit.circle_threshold_m), table_sigma);
}

}  // namespace

double trunkSurfaceBand(const TrunkModel& trunk, const ModelerConfig& config) {
  return std::max(config.fit.cylinder_threshold_m, noiseBand(trunk.noise_sigma));
}

TrunkMembership trunkMembership(const Points& pts, const std::vector<int>& region,
                                const TrunkModel& trunk, double band) {
  TrunkMembership out;
  out.cylinder.assign(region.size(), -1);
  out.on_surface.assign(region.size(), 0);
  parallelFor(static_cast<int>(region.size()), [&](int k) {
    const Eigen::Vector3d& p = pts[region[k]];
    const double s = trunk.centerline.project(p);
    for (std::size_t i = 0; i < trunk.cylinders.size(); ++i) {
      if (s >= trunk.cylinder_ranges[i].first && s < trunk.cylinder_ranges[i].second) {
        const Cylinder& c = trunk.cylinders[i];
        out.cylinder[k] = static_cast<int>(i);
        out.on_surface[k] = std::abs(axisDistance(c, p) - c.radius) < band;
        break;
      }
    }
  });
  out.points.assign(trunk.cylinders.size(), 0);
  out.inliers.assign(trunk.cylinders.size(), 0);
  for (std::size_t k = 0; k < region.size(); ++k) {
    if (out.cylinder[k] >= 0) {
      ++out.points[out.cylinder[k]];
      out.inliers[out.cylinder[k]] += out.on_surface[k];
    }
  }
  return out;
}

TrunkModel modelTrunk(const Points& pts, const std::vector<int>& region,
                      const std::vector<Eigen::Vector3d>& initial_axis, double initial_radius,
                      const ModelerConfig& config, const std::vector<double>& axis_radii,
                      const TrunkModel* earlier) {
  if (initial_axis.size() < 2 || region.size() < static_cast<std::size_t>(MIN_SLICE_POINTS)) {
    throw Error(ErrorCode::NO_TRUNK, "no trunk: too few trunk points to model");
  }
  TrunkModel trunk;
  const double h = config.trunk.slice_height_m;
  const Centerline initial(initial_axis.size() >= 3 ? smoothAxis(initial_axis, h) : initial_axis);
  const SliceBounds bounds = sliceBounds(initial_radius);
  const TrackedAxis track(initial, initial_axis, axis_radii);
  SlicedAxis sliced;
  if (earlier) {
    trunk.noise_sigma = earlier->noise_sigma;
    trunk.search_sigma = earlier->search_sigma;
    trunk.table_sigma = earlier->table_sigma;
    sliced = slicesAlong(pts, region, earlier->centerline, bounds, track, config);
  } else {
    // The noise is read on slices bounded by the trunk-wide radius alone and about their own
    // centreline, with or without a track: the calibration rig's sections are read alike (one
    // section, no track). The range noise skips the slices off the track; the bands and gates
    // that pick among clutter were set on every slice's scatter.
    sliced = refinedSlices(pts, region, initial, bounds, TrackedAxis{}, initial_radius, config);
    const TrunkNoise noise = trunkNoise(pts, region, sliced.line, sliced.slices, track, config);
    trunk.noise_sigma = noise.range;
    trunk.search_sigma = noise.search;
    // Raw radii (calibrate_diameters measuring a rig) key their rows on the rig's own reading.
    trunk.table_sigma = config.noise.correct_bias && !config.branches.raw_radius
                            ? standardNoiseReading(config, noise.range, noise.slice_radii)
                            : noise.range;
    if (!track.empty())
      sliced = refinedSlices(pts, region, initial, bounds, track, initial_radius, config);
  }
  const double sigma = trunk.noise_sigma;
  const double scatter =
      config.noise.correct_bias ? std::hypot(sigma, config.noise.beam_spread_m) : 0.0;
  trunk.scatter = scatter;
  // The trunk's RANSAC bands decide which circle a slice through clutter takes, like the
  // search's gates: they keep the reading they were set on. With the range noise alone a
  // crooked leader's slices took the wider circles around its bends, and its taper profile
  // followed them.
  double circle_threshold = config.fit.circle_threshold_m,
         cylinder_threshold = config.fit.cylinder_threshold_m;
  if (config.noise.derive_parameters) {
    circle_threshold = std::max(circle_threshold, noiseBand(trunk.search_sigma));
    cylinder_threshold = std::max(cylinder_threshold, noiseBand(trunk.search_sigma));
  }
  if (config.fit.constrain || config.noise.derive_parameters || config.noise.correct_bias) {
    const auto expected = expectedRadii(sliced.slices);
    const SliceLimits limits{circle_threshold,
                             bounds,
                             &track,
                             config.fit.constrain ? &expected : nullptr,
                             config.trunk.radius_continuity,
                             surfaceKernelSigma(trunk.table_sigma, config)};
    sliced.slices = computeSlices(pts, region, sliced, limits, trunk.table_sigma, config);
  }
  trunk.slices = sliced.slices;
  trunk.centerline = sliced.line;
  const SegmentContext segments{pts, region, sliced, bounds, cylinder_threshold, scatter, config};
  trunk.partitions = earlier ? earlier->partitions : trunkCuts(segments);
  fitCylinders(segments, trunk);
  if (trunk.cylinders.empty())
    throw Error(ErrorCode::NO_TRUNK, "no trunk: no trunk cylinder could be fitted");
  if (config.noise.correct_bias && config.trunk.taper_profile)
    applyTaperProfile(trunk, config);
  // Judged before the bound below, which may take a segment's radius off its returns (a
  // swelling) without it ceasing to be trunk.
  endWhereTheSurfaceEnds(pts, region, config, trunk);
  if (config.fit.constrain)
    boundByTheSegmentBelow(trunk.cylinders);
  return trunk;
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
