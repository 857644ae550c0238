#include "dormant_tree_modeling/modeling/modeler_config.h"

#include "dormant_tree_modeling/common/config_table.h"
#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace modeling {

namespace {

constexpr const char* WHAT = "tree modeler parameter";

void checkCalibration(const std::string& name, const RadiusCalibration& cal) {
  const auto& table = modelerConfigTable();
  if (cal.radii.empty() && cal.noise.empty() && cal.bias.empty())
    return;  // no table: no correction
  table.require(cal.valid(),
                name + ": radii and noise must be ascending and non-empty, bias must hold " +
                    "noise x radii = " + std::to_string(cal.noise.size() * cal.radii.size()) +
                    " values (has " + std::to_string(cal.bias.size()) + ")");
  for (const double b : cal.bias)
    table.require(b >= -0.05 && b <= 0.05,
                  name + " bias " + std::to_string(b) + " is outside ±0.05 m");
  table.require(cal.radii.front() >= 1e-4 && cal.radii.back() <= 1.0,
                name + " radii must lie in [0.0001, 1] m");
  table.require(cal.noise.front() >= 0.0 && cal.noise.back() <= 0.1,
                name + " noise must lie in [0, 0.1] m");
}

void addPreprocess(ConfigTable<ModelerConfig>& t) {
  using P = PreprocessConfig;
  t.group(&ModelerConfig::preprocess)
      .add("preprocess.voxel_size_m", &P::voxel_size_m, 0.0, 0.05,
           "Downsampling grid; 0 keeps every point.")
      .formerly("voxel_size")
      .add("preprocess.max_points", &P::max_points, 10000, 50000000,
           "Points modeled at most: a cloud with more after downsampling is downsampled again "
           "on a coarser grid until it fits (bounds memory and time, and says so).")
      .formerly("max_modeled_points")
      .add("preprocess.remove_clutter", &P::remove_clutter,
           "Past the paper: drop floating pixels, the ground and wires before modelling.")
      .formerly("ours_remove_clutter")
      .add("preprocess.floating_radius_m", &P::floating_radius_m, 0.001, 0.5,
           "Floating-pixel removal: neighbourhood radius.")
      .formerly("floating_radius")
      .add("preprocess.floating_min_neighbors", &P::floating_min_neighbors, 1, 1000,
           "Fewer neighbours within the radius: a floating pixel.")
      .add("preprocess.wire_min_length_m", &P::wire_min_length_m, 0.1, 100.0,
           "Straight thin horizontal runs this long are wires.")
      .formerly("wire_min_length");
}

void addNoise(ConfigTable<ModelerConfig>& t) {
  using N = NoiseConfig;
  t.group(&ModelerConfig::noise)
      .add("noise.sigma_m", &N::sigma_m, -1.0, 0.1,
           "Range noise (1 sigma); negative: estimated from the trunk.")
      .formerly("noise_sigma")
      .add("noise.beam_spread_m", &N::beam_spread_m, 0.0, 0.1,
           "Lateral scatter of returns from the beam footprint (1 sigma), taken off in quadrature "
           "where no radius table applies. 0.63 x the LMS111 beam radius at 2 m (SICK LMS1xx "
           "manual 3.6.2), calibrated on the sensor model; 0 for an ideal beam.")
      .formerly("beam_spread")
      .add("noise.derive_parameters", &N::derive_parameters,
           "Past the paper: e_t and the fit bands from the estimated noise and density.")
      .formerly("ours_derive_parameters")
      .add("noise.correct_bias", &N::correct_bias,
           "Past the paper: radii corrected for the range noise (and the calibration's "
           "footprint) instead of the plain fit.")
      .formerly("ours_correct_noise_bias");
}

void addGraph(ConfigTable<ModelerConfig>& t) {
  using G = GraphConfig;
  t.group(&ModelerConfig::graph)
      .add("graph.points_per_cluster", &G::points_per_cluster, 50, 1000000,
           "N_c = points / this (paper: about 3000 per cluster).")
      .formerly("cluster_points")
      .add("graph.split_error_m", &G::split_error_m, 1e-4, 0.1,
           "e_t: mean |d - r| of a cluster's cylinder fit that splits it (paper: 0.4 cm).")
      .formerly("split_error")
      .add("graph.merge_distance_m", &G::merge_distance_m, 0.0, 1.0,
           "d_t: clusters whose centres are closer merge (paper: 5 cm).")
      .formerly("merge_distance")
      .add("graph.min_cluster_points", &G::min_cluster_points, 6, 100000,
           "Clusters are not split below twice this.")
      .add("graph.neighbors", &G::neighbors, 4, 1000,
           "N: nearest neighbours of the interface point.")
      .formerly("graph_neighbors")
      .add("graph.n_low", &G::n_low, 0.0, 1.0, "n_L: least neighbour share for an edge (paper).")
      .add("graph.n_high", &G::n_high, 0.0, 1.0,
           "n_H: greatest neighbour share for an edge (paper); at least n_low.")
      .add("graph.psi_t_deg", &G::psi_t_deg, 1.0, 90.0,
           "psi_T: the trunk path stops at edges this far from vertical (paper: 72 deg).")
      .formerly("psi_t")
      .add("graph.kmeans_iterations", &G::kmeans_iterations, 1, 1000, "Lloyd iterations at most.")
      .add("graph.follow_diameter", &G::follow_diameter,
           "Past the paper: the trunk's top is followed by diameter, not by the most vertical "
           "edge.")
      .formerly("ours_follow_diameter");
}

void addFit(ConfigTable<ModelerConfig>& t) {
  using F = FitConfig;
  t.group(&ModelerConfig::fit)
      .add("fit.circle_threshold_m", &F::circle_threshold_m, 1e-4, 0.1,
           "RANSAC inlier band of the slice circles.")
      .formerly("circle_threshold")
      .add("fit.cylinder_threshold_m", &F::cylinder_threshold_m, 1e-4, 0.1,
           "RANSAC inlier band of trunk and branch cylinders.")
      .formerly("cylinder_threshold")
      .add("fit.ransac_iterations", &F::ransac_iterations, 10, 100000, "RANSAC circle iterations.")
      .add("fit.constrain", &F::constrain,
           "Past the paper: trunk cylinders near vertical with continuous radii, branches "
           "leaving the trunk radially.")
      .formerly("ours_constrain_ransac");
}

void addTrunk(ConfigTable<ModelerConfig>& t) {
  using T = TrunkConfig;
  t.group(&ModelerConfig::trunk)
      .add("trunk.slice_height_m", &T::slice_height_m, 0.01, 0.5, "Delta Z (paper: 3-7 cm).")
      .formerly("slice_height")
      .add("trunk.disturbance_zero_run", &T::disturbance_zero_run, 1, 100,
           "Slices of flat eta before a rise counts as a partition.")
      .add("trunk.curvature_jump", &T::curvature_jump, 0.01, 1.0,
           "Outlier-share jump along a segment that splits it.")
      .add("trunk.min_segment_length_m", &T::min_segment_length_m, 0.02, 5.0,
           "Trunk segments are not split below this.")
      .formerly("min_segment_length")
      .add("trunk.max_segment_length_m", &T::max_segment_length_m, 0.0, 10.0,
           "Longer segments are cut into equal parts (a trunk tapers and bends along metres "
           "without a disturbance to cut at); 0: off, else at least twice "
           "min_segment_length_m.")
      .formerly("trunk_max_segment_length")
      .add("trunk.max_bend_m", &T::max_bend_m, 0.0, 1.0,
           "A segment whose centreline leaves its chord by more is split where it leaves it "
           "most; 0: off.")
      .formerly("trunk_max_bend")
      .add("trunk.max_tilt_deg", &T::max_tilt_deg, 1.0, 90.0,
           "Trunk cylinders' axes within this of vertical.")
      .formerly("trunk_max_tilt")
      .add("trunk.taper_profile", &T::taper_profile,
           "With noise.correct_bias: segment radii from one robust taper profile over all "
           "slices, not each segment's median slice.")
      .formerly("trunk_taper_profile")
      .add("trunk.without_branch_bases", &T::without_branch_bases,
           "Once the branches are found, the trunk is measured again without the returns "
           "beyond its surface band that lie nearer a found branch's surface (its axis carried "
           "back to the trunk) than the trunk's.")
      .add("trunk.radius_continuity", &T::radius_continuity, 0.01, 10.0,
           "A segment's radius within this share of its neighbour's.");
}

void addBranchSearch(ConfigTable<ModelerConfig>& t) {
  using B = BranchConfig;
  t.group(&ModelerConfig::branches)
      .add("branches.shell", &B::shell,
           "Past the paper: candidates from every point in a shell around the trunk, validated.")
      .formerly("ours_branch_shell")
      .add("branches.cluster_tolerance_m", &B::cluster_tolerance_m, 0.002, 0.5,
           "Euclidean clustering of branch candidates.")
      .formerly("branch_cluster_tolerance")
      .add("branches.min_points", &B::min_points, 6, 1000000, "Smaller clusters are not branches.")
      .formerly("branch_min_points")
      .add("branches.fit_length_m", &B::fit_length_m, 0.05, 2.0,
           "A branch cylinder covers this much from the trunk surface.")
      .formerly("branch_fit_length")
      .add("branches.search_budget", &B::search_budget, 0, 1000000,
           "Re-clusterings and halvings of fused candidates per tree (a mature tree needs "
           "hundreds); candidates left are reported as \"search budget spent\".")
      .formerly("branch_search_budget")
      .add("branches.ray_split", &B::ray_split,
           "A fused candidate is first parted along its strongest ray from the trunk axis.")
      .formerly("branch_ray_split")
      .add("branches.ray_split_min_noise_m", &B::ray_split_min_noise_m, 0.0, 1.0,
           "... from this scatter about every trunk slice on (search_noise_sigma_m; below it "
           "a whorl's branches stay apart).")
      .formerly("branch_ray_split_min_noise")
      .add("branches.keep_cut_off", &B::keep_cut_off,
           "A fit cut off from the trunk by a crossing branch's extraction is kept when returns "
           "fill its way back and its axis leads into the trunk (or, when the crossing branch's "
           "returns turned the fit, the line through the whole cut-off piece does).")
      .formerly("branch_keep_cut_off")
      .add("branches.merge_curved", &B::merge_curved,
           "Two pieces of one curved branch (one centre inside the other's tube, axes within "
           "45 deg) are one, the longer kept.")
      .formerly("branch_merge_curved")
      .add("branches.steep_search", &B::steep_search,
           "What the search turned down is clustered again and searched for steep branches "
           "alone (between max_radial_angle_deg and max_steep_angle_deg from the radial).")
      .add("branches.min_relative_points", &B::min_relative_points, 0.0, 1.0,
           "Detections with fewer inliers than this share of the tree's median are dropped; "
           "0: off.")
      .formerly("branch_min_relative_points");
}

void addBranchChecks(ConfigTable<ModelerConfig>& t) {
  using B = BranchConfig;
  t.add("branches.max_radial_angle_deg", &B::max_radial_angle_deg, 1.0, 90.0,
        "Branch axis vs the direction away from the trunk.")
      .formerly("branch_max_radial_angle")
      .add("branches.max_steep_angle_deg", &B::max_steep_angle_deg, 1.0, 90.0,
           "The same for a long, clearly directed candidate (steep scaffolds); at least "
           "max_radial_angle_deg.")
      .formerly("branch_max_steep_angle")
      .add("branches.max_azimuth_deg", &B::max_azimuth_deg, 1.0, 180.0,
           "Branch axis seen along the trunk vs the direction away from it.")
      .formerly("branch_max_azimuth")
      .add("branches.min_elevation_deg", &B::min_elevation_deg, -90.0, 90.0,
           "Above the trunk's normal plane, at least (primaries leave at -20 to +45 deg).")
      .formerly("branch_min_elevation")
      .add("branches.max_diameter_ratio", &B::max_diameter_ratio, 0.1, 10.0,
           "A primary is not thicker than this share of the trunk where it leaves.")
      .formerly("branch_max_diameter_ratio")
      .add("branches.axis_gap_m", &B::axis_gap_m, 0.0, 1.0,
           "The branch axis passes this close to the trunk surface.")
      .formerly("branch_axis_gap")
      .add("branches.inner_gap_m", &B::inner_gap_m, 0.0, 1.0,
           "Shell candidates start this far out from the trunk surface.")
      .formerly("branch_inner_gap")
      .add("branches.min_length_m", &B::min_length_m, 0.0, 2.0,
           "Shorter fits are spurs or fragments (a 0.2 m primary shows about 0.1 m past the "
           "shell).")
      .formerly("branch_min_length")
      .add("branches.min_height_m", &B::min_height_m, 0.0, 5.0,
           "No primary attaches lower above the trunk base (lower: mixed pixels at the soil).")
      .formerly("branch_min_height")
      .add("branches.raw_radius", &B::raw_radius,
           "Diagnostic: raw branch RMS radii, uncorrected (what calibrate_diameters measures).")
      .formerly("branch_raw_radius");
}

ConfigTable<ModelerConfig> makeTable() {
  ConfigTable<ModelerConfig> t(WHAT, "tree_modeler");
  addPreprocess(t);
  addNoise(t);
  addGraph(t);
  addFit(t);
  addTrunk(t);
  addBranchSearch(t);
  addBranchChecks(t);
  t.topLevel()
      .add("prune_ratio", &ModelerConfig::prune_ratio, 0.0, 10.0,
           "Branch / trunk diameter above which a branch is a pruning candidate.")
      .add("seed", &ModelerConfig::seed,
           "k-means++ and RANSAC streams: equal inputs give equal models.")
      .retired({"trunk_calibration_*", "branch_calibration_*"},
               "radius tables are a sensor calibration file now (calibrate_diameters; "
               "tree_model --calibration, ~calibration_file)");
  return t;
}

}  // namespace

const ConfigTable<ModelerConfig>& modelerConfigTable() {
  static const ConfigTable<ModelerConfig> table = makeTable();
  return table;
}

bool ModelerConfig::branchTableCorrects() const {
  return fit.constrain && noise.correct_bias && !branches.raw_radius && branch_calibration.valid();
}

ModelerConfig ModelerConfig::paper() {
  ModelerConfig c;
  c.noise.derive_parameters = false;
  c.preprocess.remove_clutter = false;
  c.fit.constrain = false;
  c.graph.follow_diameter = false;
  c.noise.correct_bias = false;
  c.branches.shell = false;
  c.trunk.max_bend_m = 0.0;
  c.trunk.max_segment_length_m = 0.0;
  c.trunk.taper_profile = false;
  c.trunk.without_branch_bases = false;
  c.branches.ray_split = false;
  c.branches.keep_cut_off = false;
  c.branches.merge_curved = false;
  c.branches.steep_search = false;
  c.branches.min_relative_points = 0.0;
  return c;
}

void ModelerConfig::validate() const {
  const auto& table = modelerConfigTable();
  table.check(*this);
  table.require(graph.n_high >= graph.n_low, "graph.n_high must be at least graph.n_low");
  table.require(
      trunk.max_segment_length_m == 0.0 ||
          trunk.max_segment_length_m >= 2.0 * trunk.min_segment_length_m,
      "trunk.max_segment_length_m must be 0 or at least twice trunk.min_segment_length_m");
  table.require(branches.max_steep_angle_deg >= branches.max_radial_angle_deg,
                "branches.max_steep_angle_deg must be at least branches.max_radial_angle_deg");
  checkCalibration("trunk_calibration", trunk_calibration);
  checkCalibration("branch_calibration", branch_calibration);
}

ModelerConfig loadModelerConfig(const std::string& path) {
  ModelerConfig config;
  modelerConfigTable().load(path, config);
  config.validate();
  return config;
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
