#include "dormant_tree_modeling/modeling/tree_modeler.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <limits>
#include <numeric>
#include <optional>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/parallel.h"
#include "dormant_tree_modeling/common/statistics.h"
#include "dormant_tree_modeling/modeling/branch_model.h"
#include "dormant_tree_modeling/modeling/cluster_graph.h"
#include "dormant_tree_modeling/modeling/noise_band.h"
#include "dormant_tree_modeling/modeling/noise_bias.h"
#include "dormant_tree_modeling/modeling/point_index.h"
#include "dormant_tree_modeling/modeling/structure.h"
#include "dormant_tree_modeling/modeling/trunk_model.h"
#include "dormant_tree_modeling/modeling/trunk_search.h"

namespace dormant_tree_modeling {
namespace modeling {

namespace {

constexpr std::size_t MIN_POINTS = 100;
// The structure test: neighbour growth from 5 to 10 cm (above every scanner's range noise,
// below a trunk's length) on 2000 points.
constexpr double STRUCTURE_RADIUS_M = 0.05;
constexpr std::size_t STRUCTURE_SAMPLES = 2000;
// Halfway between a surface (2) and a volume (3): trees measure 1.7-2.0, a cloud of noise 3.
constexpr double MAX_STRUCTURE_DIMENSION = 2.5;
// A trunk whose returns scatter more than this about its fit is not a scanned surface: four
// times the LMS111's specified 1-sigma statistical error, and more than a young branch's
// radius, so no diameter would mean anything.
constexpr double MAX_NOISE_SIGMA_M = 0.05;
class Stopwatch {
 public:
  explicit Stopwatch(std::vector<std::pair<std::string, double>>& out) : out_(out) {}
  void lap(const std::string& name) {
    const auto now = std::chrono::steady_clock::now();
    out_.emplace_back(name, std::chrono::duration<double>(now - last_).count());
    last_ = now;
  }

 private:
  std::vector<std::pair<std::string, double>>& out_;
  std::chrono::steady_clock::time_point last_ = std::chrono::steady_clock::now();
};

CylinderModel toModel(const Cylinder& c, int id, std::size_t inliers, std::size_t total) {
  CylinderModel m;
  m.id = id;
  m.center = c.center;
  m.axis = c.axis;
  m.diameter = 2.0 * c.radius;
  m.length = c.length;
  m.num_points = inliers;
  m.inlier_ratio = total > 0 ? static_cast<double>(inliers) / static_cast<double>(total) : 0.0;
  return m;
}

/// What preprocessing did that the user should hear of, one sentence each.
std::vector<std::string> preprocessNotices(const PreprocessStats& s, std::size_t modeled,
                                           const ModelerConfig& config) {
  std::vector<std::string> out;
  if (s.far_outliers > 0) {
    out.push_back("dropped " + std::to_string(s.far_outliers) +
                  " stray points far outside the cloud's bulk");
  }
  if (s.capped > 0) {
    char text[200];
    std::snprintf(text, sizeof(text),
                  "%zu points modeled on a %.1f mm grid, coarser than voxel_size, to stay within "
                  "max_modeled_points (%d)",
                  modeled, 1000.0 * s.voxel_size, config.preprocess.max_points);
    out.emplace_back(text);
  }
  return out;
}

/// A branch radius within this share above MIN_BRANCH_RADIUS_M is the floor, not a measurement.
constexpr double FLOOR_TOLERANCE = 1.0 + 1e-6;

/// Whether a branch radius is the floor the noise correction stops at.
bool atFloor(double radius) {
  return radius <= MIN_BRANCH_RADIUS_M * FLOOR_TOLERANCE;
}

/// How far outside a calibration's covered radii and noise a tree may go before the model says
/// the tables were held constant there: a rod's or a section's neighbourhood.
constexpr double COVERAGE_NOISE_SLACK = 0.25;

std::string outsideRange(const char* what, const std::vector<double>& radii, double lo, double hi) {
  int below = 0, above = 0;
  for (const double r : radii) {
    below += r < lo * (1.0 - COVERAGE_RADIUS_SLACK);
    above += r > hi * (1.0 + COVERAGE_RADIUS_SLACK);
  }
  if (below + above == 0)
    return "";
  char text[256];
  std::snprintf(text, sizeof(text),
                "%d %s radii below and %d above the %.1f-%.1f mm the calibration covers: its "
                "footprint table is held constant there",
                below, what, above, 1000 * lo, 1000 * hi);
  return text;
}

/// Which calibration the diameters went through, and where the tree needed it beyond its rig;
/// sigma is the noise as the tables read it (TrunkModel::table_sigma).
DiameterCorrection describeCalibration(const ModelerConfig& config, const TreeModel& model,
                                       double estimated_sigma, double sigma) {
  DiameterCorrection d;
  d.noise_sigma = estimated_sigma;
  d.table_noise_sigma = sigma;
  if (!config.noise.correct_bias)
    return d;
  const SensorCalibration& cal = config.calibration;
  if (!cal.given()) {
    d.warnings.push_back(
        "no sensor calibration: radii corrected for range noise only, not for the beam "
        "footprint (make one with calibrate_diameters from a scan of a reference rig)");
    return d;
  }
  d.calibration = cal.name;
  d.calibration_hash = cal.hash;
  if (cal.noise_readings.empty()) {
    d.warnings.push_back("calibration " + cal.name +
                         " has no noise readings per pipe section (made by an older "
                         "calibrate_diameters): its rows hold the whole rig's noise estimate, "
                         "which the tree's does not match; make it again");
  }
  const CalibrationCoverage& c = cal.coverage;
  if (sigma < c.noise_min_m * (1.0 - COVERAGE_NOISE_SLACK) ||
      sigma > c.noise_max_m * (1.0 + COVERAGE_NOISE_SLACK)) {
    char text[256];
    std::snprintf(text, sizeof(text),
                  "estimated range noise %.1f mm is outside the %.1f-%.1f mm the calibration "
                  "covers: its footprint table is held constant there",
                  1000 * sigma, 1000 * c.noise_min_m, 1000 * c.noise_max_m);
    d.warnings.emplace_back(text);
  }
  std::vector<double> trunk, branches;
  for (const auto& t : model.trunk)
    trunk.push_back(0.5 * t.diameter);
  for (const auto& b : model.primary_branches)
    branches.push_back(0.5 * b.cylinder.diameter);
  for (const auto& w :
       {outsideRange("trunk", trunk, c.trunk_radius_min_m, c.trunk_radius_max_m),
        outsideRange("branch", branches, c.branch_radius_min_m, c.branch_radius_max_m)}) {
    if (!w.empty())
      d.warnings.push_back(w);
  }
  return d;
}

/// The branches whose diameter is no measurement (empty when none): at the floor, or read as
/// thinner branches read too, up to the widest diameter_max they were given (the tables'
/// reach at the tree's noise).
std::string floorWarning(const TreeModel& model, double estimated_sigma) {
  std::size_t unresolved = 0, at_floor = 0;
  double widest = 0.0;
  for (const auto& b : model.primary_branches) {
    if (b.measurement.diameter_resolved)
      continue;
    ++unresolved;
    at_floor += atFloor(0.5 * b.cylinder.diameter);
    widest = std::max(widest, b.measurement.diameter_max);
  }
  if (unresolved == 0)
    return {};
  char text[512];
  std::snprintf(text, sizeof(text),
                "%zu of %zu branch diameters were not measured (diameter_resolved false): at %.1f "
                "mm of estimated range noise %zu corrected to the %.0f mm floor",
                unresolved, model.primary_branches.size(), 1000 * estimated_sigma, at_floor,
                2000 * MIN_BRANCH_RADIUS_M);
  std::string out = text;
  if (unresolved > at_floor) {
    std::snprintf(text, sizeof(text),
                  ", %zu where the tables read diameters of %.0f to %.1f mm alike",
                  unresolved - at_floor, 2000 * MIN_BRANCH_RADIUS_M, 1000 * widest);
    out += text;
  }
  return out;
}

/// Which calibration the diameters went through, where the tree needed it beyond its rig, and
/// which branches it took to the floor; sigma is the noise as the tables read it
/// (TrunkModel::table_sigma).
DiameterCorrection describeCorrection(const ModelerConfig& config, const TreeModel& model,
                                      double estimated_sigma, double sigma) {
  DiameterCorrection d = describeCalibration(config, model, estimated_sigma, sigma);
  const std::string floor = floorWarning(model, estimated_sigma);
  if (!floor.empty())
    d.warnings.push_back(floor);
  return d;
}

/// Drops non-finite points (a copy only when there are some: a whole scan is hundreds of MB)
/// and preprocesses the rest into result->points, ->preprocess and ->notices.
/// @throws Error EMPTY_INPUT with fewer than MIN_POINTS before or after
void preprocessInput(const Points& input, const ModelerConfig& config, ModelResult* result) {
  std::size_t finite = 0;
  for (const auto& p : input)
    finite += p.allFinite();
  if (finite < MIN_POINTS) {
    throw Error(ErrorCode::EMPTY_INPUT,
                "cloud has " + std::to_string(finite) + " finite points; at least " +
                    std::to_string(MIN_POINTS) + " are needed to model a tree");
  }
  Points clean;
  if (finite < input.size()) {
    clean.reserve(finite);
    for (const auto& p : input) {
      if (p.allFinite())
        clean.push_back(p);
    }
  }
  result->points = preprocess(finite < input.size() ? clean : input, config, &result->preprocess);
  Points().swap(clean);
  result->notices = preprocessNotices(result->preprocess, result->points.size(), config);
  if (result->points.size() < MIN_POINTS) {
    throw Error(ErrorCode::EMPTY_INPUT, "only " + std::to_string(result->points.size()) +
                                            " points left after preprocessing");
  }
}

/// Throws "no tree found" (Error NO_TRUNK) with a printf-formatted reason.
template <typename... Args>
[[noreturn]] void throwNoTree(const char* format, Args... args) {
  char text[256];
  std::snprintf(text, sizeof(text), format, args...);
  throw Error(ErrorCode::NO_TRUNK, text);
}

/// @throws Error NO_TRUNK for points that fill a volume instead of lying on surfaces
void requireSurfaces(double dimension) {
  if (dimension > MAX_STRUCTURE_DIMENSION) {
    throwNoTree(
        "no tree found: the points fill a volume instead of lying on surfaces "
        "(neighbour growth dimension %.2f over %.0f-%.0f cm, above %.1f; scanned trees "
        "give 1.7-2.0, noise 3)",
        dimension, 100 * STRUCTURE_RADIUS_M, 200 * STRUCTURE_RADIUS_M, MAX_STRUCTURE_DIMENSION);
  }
}

/// @throws Error NO_TRUNK for a best trunk whose returns scatter beyond MAX_NOISE_SIGMA_M
void requireScannedSurface(double sigma) {
  if (sigma > MAX_NOISE_SIGMA_M) {
    throwNoTree(
        "no tree found: the returns around the best trunk candidate scatter %.0f mm "
        "(1 sigma) about its fit, over %.0f mm: no scanned surface",
        1000 * sigma, 1000 * MAX_NOISE_SIGMA_M);
  }
}

/// What Algorithm 3 models the trunk from.
struct TrunkRegion {
  std::vector<int> points;            ///< indices of the trunk region's points, sorted
  std::vector<Eigen::Vector3d> axis;  ///< initial centreline, bottom to top
  double radius = 0.0;                ///< typical trunk radius (m), 0 when unknown
  std::vector<double> radii;          ///< the radius at each axis point, when tracked
};

/// Algorithm 3's trunk region: the trunk and primary-branch clusters, the trunk clusters'
/// centroids as the axis (a lone trunk cluster's fitted axis) and their median fitted radius.
/// @throws Error NO_TRUNK for a lone trunk cluster without a cylinder fit
TrunkRegion pathRegion(const std::vector<Cluster>& clusters, const TrunkPath& path) {
  TrunkRegion r;
  for (const int c : path.trunk) {
    r.points.insert(r.points.end(), clusters[c].members.begin(), clusters[c].members.end());
    r.axis.push_back(clusters[c].centroid);
  }
  if (path.trunk.size() == 1) {
    const auto& c = clusters[path.trunk[0]];
    if (!c.fit)
      throw Error(ErrorCode::NO_TRUNK, "no trunk: the lowest cluster is not cylindrical");
    r.axis = {c.fit->center - 0.5 * c.fit->length * c.fit->axis,
              c.fit->center + 0.5 * c.fit->length * c.fit->axis};
  }
  for (const int c : path.primary)
    r.points.insert(r.points.end(), clusters[c].members.begin(), clusters[c].members.end());
  std::sort(r.points.begin(), r.points.end());
  std::vector<double> radii;
  for (const int c : path.trunk) {
    if (clusters[c].fit && clusters[c].fit->radius < MAX_TRUNK_FIT_RADIUS_M)
      radii.push_back(clusters[c].fit->radius);
  }
  std::sort(radii.begin(), radii.end());
  r.radius = radii.empty() ? 0.0 : radii[radii.size() / 2];
  return r;
}

/// Every point within `reach` (m) of the axis polyline, its ends extended by 5 cm: the trunk
/// region around a tracked trunk, not only the clusters Algorithm 2 linked.
std::vector<int> pointsNearAxis(const Points& pts, const std::vector<Eigen::Vector3d>& axis,
                                double reach) {
  const Centerline line(axis);
  // A near point's closest axis point lies within 5 cm of the vertices' box (the ends extend
  // by that much), so a point farther than reach + 5 cm from the box is not near.
  Eigen::Vector3d lo = axis.front(), hi = axis.front();
  for (const auto& c : axis) {
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c);
  }
  lo.array() -= reach + 0.06;
  hi.array() += reach + 0.06;
  std::vector<char> near(pts.size(), 0);
  parallelFor(static_cast<int>(pts.size()), [&](int i) {
    if ((pts[i].array() < lo.array()).any() || (pts[i].array() > hi.array()).any())
      return;
    double d = 0.0;
    const double s = line.project(pts[i], &d);
    near[i] = d <= reach && s >= -0.05 && s <= line.length() + 0.05;
  });
  std::vector<int> out;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    if (near[i])
      out.push_back(static_cast<int>(i));
  }
  return out;
}

/// The trunk's cylinders as the model reports them, each with its inliers among the region's
/// points in its stretch of the centreline (marked TRUNK in `classes`).
std::vector<CylinderModel> trunkCylinders(const Points& pts, const std::vector<int>& region,
                                          const TrunkModel& trunk, const ModelerConfig& config,
                                          std::vector<PointClass>* classes) {
  const TrunkMembership m = trunkMembership(pts, region, trunk, trunkSurfaceBand(trunk, config));
  for (std::size_t k = 0; k < region.size(); ++k) {
    if (m.on_surface[k])
      (*classes)[region[k]] = PointClass::TRUNK;
  }
  std::vector<CylinderModel> out;
  for (std::size_t i = 0; i < trunk.cylinders.size(); ++i)
    out.push_back(toModel(trunk.cylinders[i], static_cast<int>(i), m.inliers[i], m.points[i]));
  return out;
}

/// Whether a branch's radius is a measurement: above the floor, and, where the tables
/// corrected it, read wider than every radius they cannot tell from the floor (a wide beam
/// reads thin branches of several radii alike).
bool diameterResolved(double radius, const TrunkModel& trunk, const ModelerConfig& config) {
  if (atFloor(radius))
    return false;
  return !config.branchTableCorrects() ||
         config.branch_calibration.resolves(radius, trunk.table_sigma, MIN_BRANCH_RADIUS_M);
}

/// The narrowest and widest diameters a branch may have (m): its diameter where it was
/// measured; otherwise the floor up to the widest radius the tables cannot tell from it (all
/// apparent radii up to the floor's ambiguity read alike within a fraction of a millimetre).
std::pair<double, double> diameterRange(double radius, bool resolved, const TrunkModel& trunk,
                                        const ModelerConfig& config) {
  if (resolved)
    return {2 * radius, 2 * radius};
  const double reach =
      config.branchTableCorrects()
          ? config.branch_calibration.floorAmbiguity(MIN_BRANCH_RADIUS_M, trunk.table_sigma).radius
          : MIN_BRANCH_RADIUS_M;
  return {2 * MIN_BRANCH_RADIUS_M, 2 * std::max(reach, radius)};
}

/// A branch fit as the model reports it, measured where its axis meets the trunk, which may be
/// another segment than the one its candidate points came nearest to. The trunk diameter there
/// is interpolated: a segment's own diameter put 13-18 % of the branches on the wrong segment
/// of a tall cluster and ignored the taper along it (3.8 mm mean error at the attachment, 6 mm
/// noise, 36 trees; 0.8 mm interpolated).
PrimaryBranch primaryBranch(const BranchFit& f, const TrunkModel& trunk, int id,
                            const ModelerConfig& config) {
  PrimaryBranch pb;
  pb.cylinder = toModel(f.cylinder, id, f.inliers.size(), f.candidates);
  const double s = trunk.centerline.project(f.attachment);
  pb.trunk_segment = trunk.cylinderAt(s);
  const Cylinder& seg = trunk.cylinders[pb.trunk_segment];
  pb.measurement.attachment_height = f.attachment.z() - trunk.baseZ();
  pb.measurement.angle_to_trunk = std::acos(std::clamp(f.cylinder.axis.dot(seg.axis), -1.0, 1.0));
  pb.measurement.trunk_diameter = trunk.diameterAt(s);
  pb.measurement.diameter_ratio = pb.cylinder.diameter / pb.measurement.trunk_diameter;
  pb.measurement.prune = pb.measurement.diameter_ratio > config.prune_ratio;
  pb.measurement.diameter_resolved = diameterResolved(f.cylinder.radius, trunk, config);
  const auto range =
      diameterRange(f.cylinder.radius, pb.measurement.diameter_resolved, trunk, config);
  pb.measurement.diameter_min = range.first;
  pb.measurement.diameter_max = range.second;
  return pb;
}

/// Removes from `region` the points flagged in `on`; how many it removed.
int dropPointsOn(const std::vector<char>& on, std::vector<int>* region) {
  const auto end =
      std::remove_if(region->begin(), region->end(), [&](int i) { return on[i] != 0; });
  const auto dropped = static_cast<int>(region->end() - end);
  region->erase(end, region->end());
  return dropped;
}

/// The trunk measured again on its region without the found branches' bases
/// (branchBasePoints), with the noise read the first time: the branches were searched and
/// measured at that reading. The first model stays when none are found or the second fails.
TrunkModel withoutBranchBases(const Points& pts, const TrunkRegion& region, const TrunkModel& trunk,
                              const std::vector<BranchFit>& branches, const ModelerConfig& config) {
  std::vector<char> base(pts.size(), 0);
  for (const int k :
       branchBasePoints(pts, region.points, trunk, branches, trunkSurfaceBand(trunk, config)))
    base[k] = 1;
  std::vector<int> points = region.points;
  if (dropPointsOn(base, &points) == 0)
    return trunk;
  try {
    return modelTrunk(pts, points, region.axis, region.radius, config, region.radii, &trunk);
  } catch (const Error&) {
    return trunk;
  }
}

}  // namespace

ModelerConfig stageConfig(const ModelerConfig& config) {
  config.validate();
  ModelerConfig c = config;
  if (c.noise.correct_bias) {
    c.trunk_calibration = addFootprint(trunkNoiseBias(c), c.calibration.trunk_footprint);
    c.branch_calibration = addFootprint(branchNoiseBias(c), c.calibration.branch_footprint);
  }
  return c;
}

TreeModeler::TreeModeler(const ModelerConfig& config) : config_(stageConfig(config)) {}

ModelResult TreeModeler::model(const Cloud& cloud) const {
  Points pts;
  pts.reserve(cloud.size());
  for (const auto& p : cloud.points) {
    if (std::isfinite(p.x) && std::isfinite(p.y) && std::isfinite(p.z))
      pts.emplace_back(p.x, p.y, p.z);
  }
  return model(pts);
}

ModelResult TreeModeler::model(const Points& input) const {
  const auto start = std::chrono::steady_clock::now();
  ModelResult result;
  Stopwatch watch(result.timings);
  preprocessInput(input, config_, &result);
  const Points& pts = result.points;
  watch.lap("preprocess");

  // One index of the modeled cloud for the spacing, the graph, the trunk tracking and the
  // branch step.
  const PointIndex index(pts);
  watch.lap("index");
  result.structure_dimension =
      neighbourGrowthDimension(pts, index, STRUCTURE_RADIUS_M, STRUCTURE_SAMPLES);
  requireSurfaces(result.structure_dimension);
  watch.lap("structure");
  // Algorithm 2.
  auto clusters = initialClusters(pts, config_, medianSpacing(pts, index));
  watch.lap("kmeans");
  result.split_error = config_.noise.derive_parameters
                           ? derivedSplitError(clusters, config_.graph.split_error_m)
                           : config_.graph.split_error_m;
  clusters = splitClusters(pts, std::move(clusters), result.split_error, config_);
  clusters = mergeClusters(pts, std::move(clusters), config_.graph.merge_distance_m);
  watch.lap("split_merge");
  const auto adjacency = connectClusters(pts, index, clusters, config_);
  const TrunkPath path = findTrunkPath(clusters, adjacency, config_);
  watch.lap("graph");
  result.clusters = static_cast<int>(clusters.size());
  result.trunk_clusters = static_cast<int>(path.trunk.size());
  result.primary_clusters = static_cast<int>(path.primary.size());

  // Algorithm 3 on the trunk region: Algorithm 2's, or (ours) the points around the best
  // tracked trunk.
  TrunkRegion region = pathRegion(clusters, path);
  std::vector<TrackedTrunk> columns;
  if (config_.graph.follow_diameter) {
    if (const auto tracked = trackBestTrunk(pts, index, clusters, path, config_,
                                            &result.trunk_candidates, &columns)) {
      region.axis = tracked->centers;
      region.radius = median(tracked->radii);
      region.radii = tracked->radii;
      region.points = pointsNearAxis(pts, region.axis, trunkReach(region.radius));
    }
  }
  watch.lap("track");
  TrunkModel trunk =
      modelTrunk(pts, region.points, region.axis, region.radius, config_, region.radii);
  requireScannedSurface(trunk.search_sigma);
  // Another column's surface is taken as wide as the trunk's cylinders take theirs: the band
  // that picks a surface out of clutter.
  const double column_band =
      std::max(config_.fit.cylinder_threshold_m, noiseBand(trunk.search_sigma));
  const std::vector<char> on_columns =
      pointsOnColumns(pts, columns, TrackedTrunk{region.axis, region.radii}, column_band);
  // A post within the trunk's reach is no part of the trunk: its near side widened the slices
  // of a leader leaning to within centimetres of it. Modelled again without it.
  result.trunk_column_points = dropPointsOn(on_columns, &region.points);
  if (result.trunk_column_points > 0)
    trunk = modelTrunk(pts, region.points, region.axis, region.radius, config_, region.radii);
  result.noise_sigma = trunk.noise_sigma;
  result.table_noise_sigma = trunk.table_sigma;
  watch.lap("trunk");
  result.column_points = static_cast<int>(std::count(on_columns.begin(), on_columns.end(), 1));
  const auto branches =
      modelBranches(pts, index, trunk, region.points, config_, &result.rejected_branches,
                    result.preprocess.wire_directions, on_columns);
  watch.lap("branches");
  if (config_.trunk.without_branch_bases)
    trunk = withoutBranchBases(pts, region, trunk, branches, config_);
  watch.lap("trunk_again");

  TreeModel& model = result.model;
  model.input_points = input.size();
  result.classes.assign(pts.size(), PointClass::OTHER);
  model.trunk = trunkCylinders(pts, region.points, trunk, config_, &result.classes);
  const int first_branch_id = static_cast<int>(trunk.cylinders.size());
  for (std::size_t b = 0; b < branches.size(); ++b) {
    model.primary_branches.push_back(
        primaryBranch(branches[b], trunk, first_branch_id + static_cast<int>(b), config_));
    for (const int k : branches[b].inliers)
      result.classes[k] = PointClass::PRIMARY;
  }
  model.correction = describeCorrection(config_, model, trunk.noise_sigma, trunk.table_sigma);
  model.correction.search_noise_sigma = trunk.search_sigma;
  model.runtime_s = std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  return result;
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
