#pragma once

#include <algorithm>
#include <optional>
#include <vector>

#include "dormant_tree_modeling/modeling/geometry_fit.h"
#include "dormant_tree_modeling/modeling/modeler_config.h"
#include "dormant_tree_modeling/modeling/point_index.h"

namespace dormant_tree_modeling {
namespace modeling {

/// @brief A trunk's least radius, m.
constexpr double MIN_TRUNK_RADIUS = 0.003;
/// @brief Slice circles are searched between these shares of the trunk clusters' radius (a
/// circle through branch points can be any size); the noise-bias tables run the same search.
constexpr double SLICE_MIN_RADIUS_SHARE = 0.3;
constexpr double SLICE_MAX_RADIUS_SHARE = 2.5;

/// @brief A polyline with arc-length projection, used as the trunk's centreline.
class Centerline {
 public:
  Centerline() = default;
  /// @param vertices at least two, bottom to top
  explicit Centerline(std::vector<Eigen::Vector3d> vertices);
  /// @brief Arc length of the projection of p (may be < 0 or > length() beyond the ends) and
  /// the distance from p to the polyline.
  double project(const Eigen::Vector3d& p, double* distance = nullptr) const;
  /// @brief Point at arc length s (extrapolated beyond the ends).
  Eigen::Vector3d pointAt(double s) const;
  /// @brief Unit direction at arc length s.
  Eigen::Vector3d directionAt(double s) const;
  double length() const { return cumulative_.empty() ? 0.0 : cumulative_.back(); }
  const std::vector<Eigen::Vector3d>& vertices() const { return vertices_; }

 private:
  std::size_t segmentAt(double s) const;
  /// Squared distance from p to segment i (the end segments extended) and the arc length of
  /// the closest point.
  double segmentDistance2(std::size_t i, const Eigen::Vector3d& p, double* s) const;
  struct Segment {
    Eigen::Vector3d direction = Eigen::Vector3d::Zero();  // unit, from vertex i to i + 1
    double length = 0.0;
  };
  std::vector<Eigen::Vector3d> vertices_;
  std::vector<Segment> segments_;
  std::vector<double> cumulative_;
  bool rising_ = false;  ///< vertex heights strictly increase: project() searches by height
};

/// @brief One slice of Algorithm 3 step 1.
struct Slice {
  double s0 = 0.0;  ///< arc length of the slice's lower bound
  int points = 0;
  int outliers = 0;            ///< eta: points off the slice's RANSAC circle
  double outlier_share = 0.0;  ///< outliers / points
  bool has_circle = false;
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  ///< circle centre in 3-D
  double radius = 0.0;
  /// Radius with the sensor's systematic error taken off (ModelerConfig::trunk_calibration);
  /// equals radius when no noise estimate was given or the correction is off.
  double corrected_radius = 0.0;
};

/// @brief The trunk as Algorithm 3 models it.
struct TrunkModel {
  Centerline centerline;  ///< refined by the slice circles
  std::vector<Slice> slices;
  std::vector<double> partitions;   ///< arc lengths of the segment bounds, first 0, last = top
  std::vector<Cylinder> cylinders;  ///< one per segment, bottom to top (failed fits left out)
  std::vector<std::pair<double, double>> cylinder_ranges;  ///< arc-length range of each cylinder
  /// Range noise estimate (m), read on the slices whose circle keeps to the trunk's tracked
  /// radius: the fits' bands, the scatter taken off radii and the tables take it.
  double noise_sigma = 0.0;
  /// The scatter about every slice circle (m), those through whorls and around scaffolds
  /// included: what the trunk's RANSAC bands, the branch search's noise gates and its
  /// extraction reach were set on, and what tells a scanned surface from clutter. Above
  /// noise_sigma on a tree with whorls.
  double search_sigma = 0.0;
  /// The estimate as the radius tables read it (m): what a 5 cm slice gives for the same noise
  /// (standardNoiseReading: through the calibration rig's readings, or without a calibration
  /// the estimator's modelled ones); with raw branch radii (calibrate_diameters measuring a rig)
  /// or without the bias correction, noise_sigma.
  double table_sigma = 0.0;
  /// Total scatter removed from radii: sqrt(noise_sigma^2 + beam_spread^2) when the bias
  /// correction is on, else 0 (m).
  double scatter = 0.0;

  /// @brief Height of the trunk's base: the lowest end of its cylinders (m); heights on the
  /// tree (attachment heights, the lowest primary) count from here.
  double baseZ() const;
  /// @brief Index of the cylinder whose arc-length range holds s, the nearest one when s falls
  /// between or beyond them; -1 without cylinders.
  int cylinderAt(double s) const;
  /// @brief Trunk diameter at arc length s (m): linear between the cylinders' middles (each
  /// cylinder's radius is its mean over a taper), the end cylinders' beyond their middles; 0
  /// without cylinders.
  double diameterAt(double s) const;
};

/// @brief One slice's circle as the trunk step measures it.
struct SliceCircle {
  Circle circle;         ///< in the slice plane
  int inliers = 0;       ///< of the RANSAC circle
  bool surface = false;  ///< the radius is the surface mode (surfaceCircle), not RANSAC's
};

/// @brief The trunk step's estimator of one cross-section: a RANSAC circle; its centre from the
/// disc's trimmed mean where the noise the band stands for (sigmaOfBand(options.threshold))
/// exceeds a fifth of the radius; with
/// `surface`, the mode circle of the surface (surfaceCircle, bandwidth `surface_sigma`, or
/// sigmaOfBand(threshold) when 0) within [min_radius, max_radius]. The noise model
/// (noise_bias.h) runs this very estimator.
/// @param surface_sigma the noise (m) the surface mode's kernel is for; 0: the band's
/// @return nothing when RANSAC finds no circle
std::optional<SliceCircle> measureSliceCircle(const Points2& plane,
                                              const CircleRansacConfig& options, bool surface,
                                              double min_radius, double max_radius,
                                              double surface_sigma = 0.0);

/// @brief Residual-based estimate of the range noise from the slice circles of thick trunk
/// parts: 1.4826 MAD of the radial residuals, x sqrt(3/2) because a return's radial residual
/// carries on average 2/3 of its range variance. Nothing when too few slices qualify.
/// @param slice_radii when given, receives the quartiles of the radii of the slices the
/// residuals came from (m)
double estimateNoiseSigma(const Points& pts, const Centerline& line,
                          const std::vector<Slice>& slices, double slice_height,
                          std::vector<double>* slice_radii = nullptr);

/// @brief Partition arc lengths from eta (step 2): where a positive derivative follows a run of
/// at least `zero_run` near-zero derivatives. Includes 0 and the top.
std::vector<double> disturbancePartitions(const std::vector<Slice>& slices, double slice_height,
                                          int zero_run, double top);

/// @brief Slices in a row without an acceptable circle that end a track.
constexpr int TRACK_MAX_MISSES = 4;

/// @brief Result of trackTrunk().
struct TrackedTrunk {
  std::vector<Eigen::Vector3d> centers;  ///< accepted slice centres, bottom to top
  std::vector<double> radii;             ///< raw circle radius at each centre
};

/// @brief Follow the trunk upwards slice by slice from a start (our alternative to Algorithm
/// 2's path above its first clusters): predict the next centre along the current direction,
/// fit a RANSAC circle there whose radius continues the trunk's (0.6x..1.25x: the leader is
/// the thick continuation, a thin shoot is not), update centre, direction and radius, and stop
/// after `max_misses` slices without an acceptable circle.
/// @param index spatial index over pts
/// @param trust_radius the first circle too stays near `radius` (0.6x..1.6x) instead of taking
///        any trunk radius: the retry for a start whose free first circle took in clutter
TrackedTrunk trackTrunk(const Points& pts, const PointIndex& index, const Eigen::Vector3d& start,
                        const Eigen::Vector3d& direction, double radius, double threshold,
                        const ModelerConfig& config, int max_misses = TRACK_MAX_MISSES,
                        bool trust_radius = false);

/// @brief A track (bottom to top) resumed past where a whorl ended it: a whorl's branch bases
/// pull a slice's centre aside, and the track's direction with it, until the trunk's own circle
/// above lies outside the window. When the last circle lies more than half the radius off the
/// line through the six circles beneath the last two, those two are dropped and trackTrunk()
/// goes on above the track's end along that line (their median radius trusted); kept when it
/// climbs more than a slice further, up to three times.
/// @param track as trackTrunk() returned it, ordered bottom to top
/// @param threshold the circle band (m), as given to trackTrunk()
/// @return the resumed track, or `track` itself when nothing climbs further
TrackedTrunk resumePastWhorls(const Points& pts, const PointIndex& index, TrackedTrunk track,
                              double threshold, const ModelerConfig& config);

/// @brief The chosen trunk's track resumed past whorls (resumePastWhorls) and past a fork
/// where it took a branch: a steep scaffold nearly as thick as the leader draws the circles
/// onto itself, and the track ends where the branch does. When no whorl pulled it, the track is
/// tried again from each of its circles up to 1 m below its end off whose line beneath (the
/// six circles under it) the end lies, along that line from 10 cm above the circle; a climb is
/// kept when it holds more circles than it drops (the leader above a fork is longer than the
/// branch) and they are no thicker than the line's by more than the taper's 10 % swell (a
/// crown's forks are), the highest such. Up to three times. Only for the chosen track: on every
/// track, one around clutter beside a trunk's base would climb on along its line and compete.
/// @param track as trackTrunk() returned it, ordered bottom to top
/// @param threshold the circle band (m), as given to trackTrunk()
/// @return the resumed track, or `track` itself when nothing climbs further
TrackedTrunk resumePastWhorlsAndForks(const Points& pts, const PointIndex& index,
                                      TrackedTrunk track, double threshold,
                                      const ModelerConfig& config);

/// @brief The track's first `kept` circles, climbed on from there along the line through the
/// six circles beneath and resumed past whorls and forks (resumePastWhorlsAndForks): every
/// circle from `kept` on is measured again, on `pts`, which may leave out what pulled the track
/// aside (another column's surface).
/// @param track ordered bottom to top
/// @param kept circles kept, at least six and at most the track's
/// @param threshold the circle band (m), as given to trackTrunk()
/// @return the new track; nothing when `kept` is out of range or the climb finds no circle
std::optional<TrackedTrunk> climbAgainFrom(const Points& pts, const PointIndex& index,
                                           const TrackedTrunk& track, std::size_t kept,
                                           double threshold, const ModelerConfig& config);

/// @brief The trunk's neighbourhood reaches this many radii from its axis ...
constexpr double TRUNK_REACH_RADII = 3.0;
/// @brief ... and at least this far (m) beyond its surface.
constexpr double TRUNK_REACH_MIN_GAP_M = 0.05;

/// @brief The trunk's neighbourhood (m from its axis) at radius `radius` (m). Slices, tracks
/// and the trunk region look this far: branch bases and noise lie within it, the next tree's
/// wood does not.
inline double trunkReach(double radius) {
  return std::max(TRUNK_REACH_RADII * radius, radius + TRUNK_REACH_MIN_GAP_M);
}

/// @brief A trunk cylinder is trunk only where its surface holds at least this share of the
/// returns in its stretch of the centreline. Where a track runs on past the trunk's top, into
/// a real crown's forks, the last cylinders stand among the stems: 0-18 % on the real
/// adtree_tree1 scan, 0.2-0.4 m off its trunk's axis.
constexpr double MIN_TRUNK_SURFACE_SHARE = 0.15;

/// @brief Where each region point lies on the trunk: the cylinder whose arc-length range
/// holds its projection on the centreline (-1: none), and whether it lies within the surface
/// band of that cylinder; and per cylinder, how many do.
struct TrunkMembership {
  std::vector<int> cylinder;         ///< per region point
  std::vector<char> on_surface;      ///< per region point
  std::vector<std::size_t> points;   ///< per cylinder: region points in its stretch
  std::vector<std::size_t> inliers;  ///< per cylinder: those on its surface
};

/// @brief The band (m) about a trunk cylinder's surface that its returns lie in: the fit's
/// cylinder threshold or the band of the estimated range noise, the wider.
double trunkSurfaceBand(const TrunkModel& trunk, const ModelerConfig& config);

/// @brief Each region point's cylinder and whether it lies on its surface (all cores).
/// @param band half-width of the surface band (m), trunkSurfaceBand()
TrunkMembership trunkMembership(const Points& pts, const std::vector<int>& region,
                                const TrunkModel& trunk, double band);

/// @brief Algorithm 3 steps 1-4 on the trunk region.

/// @param pts the modeled cloud
/// @param region indices of trunk (and primary-cluster) points
/// @param initial_axis initial centreline points, bottom to top (e.g. trunk cluster centroids;
///        smoothed by a robust cubic fit)
/// @param initial_radius typical trunk radius (e.g. median of the trunk clusters' fits), or 0;
///        slice circles stay within 0.3x..2.5x of it
/// @param axis_radii the radius measured at each initial axis point (a track's circles), or
///        none; where given, a slice's circle stays within 0.3x..2.5x of the median of the
///        radii within 15 cm of it, and its centre within 0.3 such radii of the centreline
///        (the noise estimate still reads slices bounded by initial_radius alone)
/// @param earlier an earlier model of this trunk, or null: its centreline, its noise readings
///        (noise_sigma, search_sigma, table_sigma) and its partitions are kept instead of
///        being found again (the trunk measured again on fewer of its points)
/// @return the trunk up to its highest cylinder whose surface holds MIN_TRUNK_SURFACE_SHARE of
///         its stretch's returns, judged before a segment's radius is bounded by the one below
///         (the lowest cylinder is always kept)
/// @throws Error NO_TRUNK when no trunk cylinder can be fitted
TrunkModel modelTrunk(const Points& pts, const std::vector<int>& region,
                      const std::vector<Eigen::Vector3d>& initial_axis, double initial_radius,
                      const ModelerConfig& config, const std::vector<double>& axis_radii = {},
                      const TrunkModel* earlier = nullptr);

}  // namespace modeling
}  // namespace dormant_tree_modeling
