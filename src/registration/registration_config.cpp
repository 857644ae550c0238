#include <algorithm>
#include <cmath>

#include "dormant_tree_modeling/common/config_table.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/registration/multi_view.h"

namespace dormant_tree_modeling {
namespace registration {

namespace {

ConfigTable<IcpConfig> makeIcpTable() {
  using I = IcpConfig;
  ConfigTable<I> t("ICP parameter", "");
  t.add("voxels_m", &I::voxels_m, 0.001, 1.0,
        "Voxel of each level, coarse to fine; the source runs one level coarser.")
      .formerly("icp_voxels")
      .add("distance_factor", &I::distance_factor, 0.5, 100.0,
           "Correspondence limit = this x the level's voxel (a wide basin first, a tight fit "
           "last).")
      .formerly("icp_distance_factor")
      .add("max_iterations", &I::max_iterations, 1, 10000, "Per level.")
      .formerly("icp_max_iterations")
      .add("trim", &I::trim, 0.01, 1.0, "Share of the closest pairs used.")
      .formerly("icp_trim")
      .add("huber_m", &I::huber_m, 1e-4, 1.0,
           "Residuals beyond count linearly (robust to clutter).")
      .formerly("icp_huber")
      .add("normal_neighbors", &I::normal_neighbors, 5, 1000, "k of the PCA normals.")
      .formerly("icp_normal_neighbors")
      .add("across_cos", &I::across_cos, -1.0, 1.0,
           "View directions meeting below this cosine were seen from opposite sides: such pairs "
           "count only their offset across the ray (point-to-ray).")
      .formerly("icp_across_cos")
      .add("overlap_distance_m", &I::overlap_distance_m, 1e-4, 1.0,
           "A point overlaps when the other views come this close (about 2.5 sigma of the range "
           "noise).")
      .formerly("icp_overlap_distance")
      .add("min_rotation_step_deg", &I::min_rotation_step_deg, 1e-6, 10.0,
           "Converged below both steps (finest level; coarser levels scale them).")
      .formerly("icp_min_rotation_step")
      .add("min_translation_step_m", &I::min_translation_step_m, 1e-7, 1.0,
           "Converged below both steps (finest level).")
      .formerly("icp_min_translation_step")
      .add("axis_pairs", &I::axis_pairs,
           "Finest level: pair branch axes of opposite sides (the depth along the rays that "
           "point pairs leave free).")
      .formerly("icp_axis_pairs")
      .add("axis_max_angle_deg", &I::axis_max_angle_deg, 0.1, 89.9,
           "Paired axes at most this far from parallel.")
      .formerly("icp_axis_max_angle_deg");
  return t;
}

ConfigTable<AxisConfig> makeAxisTable() {
  using A = AxisConfig;
  ConfigTable<A> t("branch axis parameter", "");
  t.add("patch_m", &A::patch_m, 0.005, 1.0, "Neighbourhood diameter of one axis sample.")
      .formerly("axis_patch")
      .add("min_points", &A::min_points, 5, 100000, "Fewer points in a patch: no sample.")
      .formerly("axis_min_points")
      .add("linearity", &A::linearity, 1.0, 1000.0,
           "PCA: largest / second eigenvalue at least this (a stick, not a plane).")
      .formerly("axis_linearity")
      .add("max_view_cos", &A::max_view_cos, 0.0, 1.0,
           "|axis . view direction| at most this (0.5: the axis at least 60 deg from the rays).")
      .formerly("axis_max_view_cos")
      .add("min_view_agreement", &A::min_view_agreement, 0.0, 1.0,
           "Mean resultant length of the patch's view directions at least this (one side).")
      .formerly("axis_min_view_agreement")
      .add("min_radius_m", &A::min_radius_m, 0.0, 1.0, "Thinner samples are dropped.")
      .formerly("axis_min_radius")
      .add("max_radius_m", &A::max_radius_m, 0.001, 1.0,
           "Thicker samples are dropped (trunk or fork: plain point pairs serve there).")
      .formerly("axis_max_radius");
  return t;
}

ConfigTable<CoarseSearchConfig> makeCoarseTable() {
  using C = CoarseSearchConfig;
  ConfigTable<C> t("coarse search parameter", "");
  t.add("cell_m", &C::cell_m, 0.005, 1.0, "Occupancy grid cell.")
      .formerly("coarse_cell")
      .add("yaw_window_deg", &C::yaw_window_deg, 0.0, 180.0,
           "Headings within this of the hint (hints may be 20 deg off per station).")
      .formerly("coarse_yaw_window_deg")
      .add("yaw_step_deg", &C::yaw_step_deg, 0.01, 90.0, "Heading step.")
      .formerly("coarse_yaw_step_deg")
      .add("xy_window_m", &C::xy_window_m, 0.0, 100.0,
           "Positions within this of the hint (hints may be 0.5 m off).")
      .formerly("coarse_xy_window")
      .add("z_window_m", &C::z_window_m, 0.0, 100.0, "Heights within this of the hint.")
      .formerly("coarse_z_window")
      .add("z_window_unhinted_m", &C::z_window_unhinted_m, 0.0, 100.0,
           "Heights searched without a hint, around the centroids.")
      .formerly("coarse_z_window_unhinted")
      .add("z_step_m", &C::z_step_m, 0.001, 10.0, "Height step.")
      .formerly("coarse_z_step")
      .add("candidates", &C::candidates, 1, 100, "Best distinct poses returned.")
      .formerly("coarse_candidates")
      .add("second_place_m", &C::second_place_m, 0.01, 100.0,
           "The best heading's second place, this far from its best at least, is tried too: a "
           "row of trees that repeats within the window shows there.");
  return t;
}

ConfigTable<RegistrationConfig> makeRegistrationTable() {
  using R = RegistrationConfig;
  ConfigTable<R> t("registration parameter", "registration");
  t.include("icp", &R::icp, icpConfigTable())
      .include("axes", &R::axes, axisConfigTable())
      .include("coarse", &R::coarse, coarseSearchConfigTable())
      .add("candidate_levels", &R::candidate_levels, 1, 100,
           "ICP levels run on every coarse candidate; at most the number of ICP levels.")
      .add("refinement_rounds", &R::refinement_rounds, 0, 100,
           "Joint rounds: every station against all the others.")
      .add("min_points", &R::min_points, 10, 100000000,
           "Fewer points at the finest level: the station is left out.")
      .add("min_overlap", &R::min_overlap, 0.0, 1.0,
           "Share of a station's points on the others, or it is left out.")
      .add("max_rmse_m", &R::max_rmse_m, 1e-4, 1.0,
           "Point-to-plane rmse above this: the station is left out.")
      .formerly("max_rmse")
      .add("ambiguity_overlap_share", &R::ambiguity_overlap_share, 0.0, 1.0,
           "A candidate ending coarse.second_place_m or more from the best and fitting with this "
           "share of its overlap, or more: the station is left out as ambiguous (a row that "
           "repeats within the search window). 1 keeps only exact ties out.")
      .add("use_hints", &R::use_hints, "False: ignore the platform hints (global search).")
      .retired({"beam_exit", "beam_divergence", "silhouette_fraction"},
               "the silhouette growth comes from the sensor calibration file "
               "(calibrate_diameters --scan RIG_VIEWS_DIR)");
  return t;
}

}  // namespace

const ConfigTable<IcpConfig>& icpConfigTable() {
  static const ConfigTable<IcpConfig> table = makeIcpTable();
  return table;
}

const ConfigTable<AxisConfig>& axisConfigTable() {
  static const ConfigTable<AxisConfig> table = makeAxisTable();
  return table;
}

const ConfigTable<CoarseSearchConfig>& coarseSearchConfigTable() {
  static const ConfigTable<CoarseSearchConfig> table = makeCoarseTable();
  return table;
}

const ConfigTable<RegistrationConfig>& registrationConfigTable() {
  static const ConfigTable<RegistrationConfig> table = makeRegistrationTable();
  return table;
}

void IcpConfig::validate() const {
  icpConfigTable().check(*this);
}

void CoarseSearchConfig::validate() const {
  coarseSearchConfigTable().check(*this);
}

void AxisConfig::validate() const {
  axisConfigTable().check(*this);
  axisConfigTable().require(max_radius_m > min_radius_m, "max_radius_m must exceed min_radius_m");
  axisConfigTable().require(
      std::abs(silhouette_growth_m) <= 0.05 && std::abs(silhouette_growth_per_m) <= 0.05,
      "silhouette growth (from the calibration) must be within ±0.05 m and ±0.05 m per m");
  // The limit is the growth's line scaled, so its slope may be as small and negative as a
  // fitted growth per m.
  axisConfigTable().require(max_width_m >= 0.0 && std::abs(max_width_per_m) <= 0.1,
                            "silhouette width limit (from the calibration) must be at least 0 m "
                            "and within ±0.1 m per m");
  axisConfigTable().require(modeling::validDiameterGain(silhouette_diameter_gain),
                            "silhouette diameter gain (from the calibration) must be within " +
                                modeling::diameterGainRange());
}

void RegistrationConfig::validate() const {
  registrationConfigTable().check(*this);
  axes.validate();
  registrationConfigTable().require(candidate_levels <= static_cast<int>(icp.voxels_m.size()),
                                    "candidate_levels must be at most the number of ICP levels");
}

RegistrationConfig loadRegistrationConfig(const std::string& path) {
  RegistrationConfig c;
  registrationConfigTable().load(path, c);
  c.validate();
  return c;
}

bool applySensorCalibration(const modeling::SensorCalibration& calibration,
                            RegistrationConfig& config) {
  if (!calibration.silhouette.measured)
    return false;
  const auto& s = calibration.silhouette;
  config.axes.silhouette_growth_m = s.depth_share * s.growth_m;
  config.axes.silhouette_growth_per_m = s.depth_share * s.growth_per_m;
  config.axes.silhouette_diameter_gain = s.diameter_gain;
  // The silhouette model was measured on the rig's rods: a wider silhouette is beyond it, and
  // beyond what an axis sample's patch holds whole.
  const double rods = calibration.coverage.branch_radius_max_m;
  if (rods > 0.0) {
    const double slack = 1.0 + modeling::COVERAGE_RADIUS_SLACK;
    config.axes.max_width_m = slack * (2.0 * s.diameter_gain * rods + s.growth_m);
    config.axes.max_width_per_m = slack * s.growth_per_m;
  }
  return true;
}

}  // namespace registration
}  // namespace dormant_tree_modeling
