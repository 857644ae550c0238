#pragma once

#include <cstdint>
#include <string>

#include "dormant_tree_modeling/modeling/radius_calibration.h"
#include "dormant_tree_modeling/modeling/sensor_calibration.h"

namespace dormant_tree_modeling {
namespace modeling {

/// @brief Every parameter of the tree modeler. Defaults are the paper's values (Medeiros et
/// al., docs/algorithms.md) where the paper tuned one; the `ours_*` switches turn on what we
/// add past the paper, each separately so its effect can be measured. Lengths in m, angles in
/// degrees.
struct ModelerConfig {
  // --- Preprocessing -------------------------------------------------------------------
  double voxel_size = 0.004;  ///< downsampling grid; 0 keeps every point
  /// Points modeled at most: a cloud with more after downsampling is downsampled again on a
  /// coarser grid until it fits, which bounds the modeler's memory and time (and says so)
  int max_modeled_points = 2000000;
  // --- Algorithm 2: clusters, graph, trunk path ---------------------------------------
  int cluster_points = 3000;     ///< N_c = points / cluster_points (paper: ~3000 per cluster)
  double split_error = 0.004;    ///< e_t: mean |d - r| of a cluster's cylinder fit that splits it
  double merge_distance = 0.05;  ///< d_t: clusters whose centres are closer merge
  int min_cluster_points = 40;   ///< clusters are not split below twice this
  int graph_neighbors = 30;      ///< N: nearest neighbours of the interface point
  double n_low = 0.3;            ///< n_L: lower bound of the neighbour share for an edge
  double n_high = 0.7;           ///< n_H: upper bound
  double psi_t = 72.0;           ///< psi_T: stop the trunk path at edges this far from vertical
  int kmeans_iterations = 30;    ///< Lloyd iterations at most
  // --- Algorithm 3: slices, partitions, cylinders, branches ---------------------------
  double slice_height = 0.05;         ///< Delta Z (paper: 3-7 cm)
  double circle_threshold = 0.008;    ///< RANSAC inlier band of the slice circles
  int ransac_iterations = 200;        ///< RANSAC circle iterations
  double cylinder_threshold = 0.012;  ///< RANSAC inlier band of trunk and branch cylinders
  int disturbance_zero_run = 2;       ///< slices of flat eta before a rise counts as a partition
  double curvature_jump = 0.25;       ///< outlier-share jump along a segment that splits it
  double min_segment_length = 0.15;   ///< trunk segments are not split below this
  double branch_cluster_tolerance = 0.012;  ///< Euclidean clustering of branch candidates
  int branch_min_points = 25;               ///< smaller clusters are not branches
  double branch_fit_length = 0.30;  ///< a branch cylinder covers this much from the trunk surface
  // --- Past the paper (each switchable) ----------------------------------------------
  bool ours_derive_parameters = true;  ///< e_t, thresholds from the estimated noise and density
  bool ours_remove_clutter = true;     ///< floating pixels, ground, wires before modelling
  bool ours_constrain_ransac = true;   ///< trunk near vertical, radius continuity, branches radial
  bool ours_follow_diameter = true;  ///< trunk top followed by diameter, not the most vertical edge
  bool ours_correct_noise_bias =
      true;                       ///< radius sqrt(mean d^2 - sigma^2) instead of the plain fit
  bool ours_branch_shell = true;  ///< branch candidates from all points around the trunk, validated
  double noise_sigma = -1.0;      ///< range noise (m); negative: estimated from the trunk
  /// Lateral scatter of returns (m, 1 sigma) from the beam footprint: a partly hit beam reports
  /// its range along the beam centre, so thin objects look wider. Subtracted in quadrature with
  /// the range noise from every radius. Default: 0.63 x the LMS111 beam radius at the 2 m
  /// working range (8 mm + 15 mrad, SICK LMS1xx manual 3.6.2), calibrated on the sensor model;
  /// re-calibrate against calipers in the field, 0 for an ideal beam.
  double beam_spread = 0.012;
  /// The scanner's footprint calibration (calibrate_diameters; loaded from a file by the tools
  /// and the node, not a key of the parameter YAML). Empty (the default): radii are corrected
  /// for range noise alone and the model says so.
  SensorCalibration calibration;
  /// The radius bias the trunk step takes off each slice (apparent minus true, over true radius
  /// and estimated noise): TreeModeler sets it to the noise part (trunkNoiseBias) plus the
  /// calibration's trunk footprint when ours_correct_noise_bias is on. Set by hand only when
  /// calling the stages directly; empty: raw radii.
  RadiusCalibration trunk_calibration;
  /// The same for the branch step's raw RMS radius (branchNoiseBias plus the branch
  /// footprint); empty: the moment less beam_spread and noise in quadrature instead.
  RadiusCalibration branch_calibration;
  /// Diagnostic: report branches' raw RMS radius, uncorrected (what calibrate_diameters
  /// measures to build branch_calibration).
  bool branch_raw_radius = false;

  double trunk_max_tilt = 30.0;  ///< trunk cylinders' axes within this of vertical
  /// A trunk segment whose centreline leaves the chord between its ends by more than this (m)
  /// is split where it leaves it most (a leader that wanders off a straight line: one cylinder
  /// over the bend lies centimetres off the wood and the branch search misplaces the trunk
  /// surface). 0: off (the paper's segments).
  double trunk_max_bend = 0.03;
  /// A trunk segment longer than this (m) is cut into equal parts no longer: a trunk tapers
  /// and bends along metres without a disturbance to cut at, and one cylinder over 2-3 m sits
  /// centimetres off the wood and too wide at its top. 0: off (the paper's segments).
  double trunk_max_segment_length = 0.9;
  /// With ours_correct_noise_bias: trunk segment radii from one smooth taper profile fitted to
  /// all slices (robust to slices through branch bases), not each segment's median slice.
  bool trunk_taper_profile = true;
  double radius_continuity =
      0.35;  ///< a trunk segment's radius within this share of its neighbour's
  /// Re-clusterings of what is left after a branch is taken out of a candidate cluster, and
  /// halvings of candidates that fit no branch, per tree: a bound on the work. A real tree
  /// needs hundreds (a mature tree lost a third of its branches at 400); candidates left
  /// unsplit are reported with "(search budget spent)"
  int branch_search_budget = 4000;
  /// A candidate that fits no branch is first parted along the strongest ray from the trunk
  /// axis through it (a Hough transform: the branches of a whorl fuse near the trunk at
  /// centimetre noise), and only then halved by position.
  bool branch_ray_split = true;
  /// ... from this estimated range noise on (m): below it the whorl's branches stay apart, and
  /// rays through the clutter of a cloud's few fused candidates pass as branches more often
  /// than they part real ones (3 and 6 mm noise: F1 -0.1 to -0.5).
  double branch_ray_split_min_noise = 0.008;
  /// A fit whose points start farther than branch_inner_gap + 5 cm off the trunk surface is
  /// kept when returns fill its way back to the trunk and part of that way lies off every
  /// accepted branch: at centimetre noise a branch crossing it near the trunk takes its near
  /// part out with its own points. Off: such fits are turned down ("not at the surface").
  bool branch_keep_cut_off = true;
  /// Two detections that are pieces of one curved branch (curvedPieces(): one centre inside
  /// the other's tube, axes within 45 deg) are one; the longer is kept. Off: only duplicates
  /// within 25 deg of each other are merged (sameBranch()).
  bool branch_merge_curved = true;
  /// A detection with fewer inliers than this fraction of the median over the tree's
  /// detections is dropped (a shoot on a primary, a neighbour's branch tip, a streak of mixed
  /// pixels); 0: off. Needs at least 4 detections.
  double branch_min_relative_points = 0.25;
  double branch_max_radial_angle = 60.0;  ///< branch axis vs the direction away from the trunk
  /// The same bound (deg) for a candidate whose points form a long, clearly directed cluster
  /// (a steep scaffold of a central leader leaves more upwards than outwards).
  double branch_max_steep_angle = 75.0;
  /// Branch axis seen along the trunk (elevation removed) vs the direction away from it, deg.
  double branch_max_azimuth = 20.0;
  double branch_min_elevation = -30.0;  ///< deg above the trunk's normal plane (primaries: >= -20)
  double branch_max_diameter_ratio = 1.0;  ///< a primary is not thicker than the trunk there
  double branch_axis_gap = 0.10;    ///< branch axis must pass this close to the trunk surface
  double branch_min_length = 0.08;  ///< shorter fits are fragments (a 0.2 m primary shows ~0.1 m)
  double branch_min_height = 0.3;   ///< no primary attaches lower above the trunk base (m)
  double branch_inner_gap =
      0.05;  ///< shell branch candidates start this far out from the trunk surface

  double floating_radius = 0.02;   ///< floating-pixel removal: neighbourhood radius
  int floating_min_neighbors = 4;  ///< fewer neighbours within the radius: a floating pixel
  double wire_min_length = 1.2;    ///< straight thin horizontal runs this long are wires
  // --- Measurements ---------------------------------------------------------------------
  double prune_ratio =
      0.5;                 ///< branch / trunk diameter above which a branch is a pruning candidate
  std::uint64_t seed = 1;  ///< k-means++ and RANSAC streams: equal inputs give equal models

  /// @brief The paper's method alone: every `ours_*` switch off.
  static ModelerConfig paper();

  /// @brief @throws Error INVALID_ARGUMENT naming the parameter, its value and the valid range.
  void validate() const;
};

/// @brief Load a config from YAML: a map of the field names above (a `tree_modeler:` top-level
/// key is also accepted); missing keys keep their defaults, unknown keys are an error.
/// @throws Error FILE_NOT_FOUND, PARSE_ERROR, INVALID_ARGUMENT
ModelerConfig loadModelerConfig(const std::string& path);

}  // namespace modeling
}  // namespace dormant_tree_modeling
