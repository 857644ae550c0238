#pragma once

#include <cstdint>
#include <string>

#include "dormant_tree_modeling/modeling/radius_calibration.h"
#include "dormant_tree_modeling/modeling/sensor_calibration.h"

namespace dormant_tree_modeling {

template <typename Config>
class ConfigTable;

namespace modeling {

/// @brief Downsampling and clutter removal before modelling.
struct PreprocessConfig {
  double voxel_size_m = 0.004;  ///< downsampling grid; 0 keeps every point
  /// Points modeled at most: a cloud with more after downsampling is downsampled again on a
  /// coarser grid until it fits, which bounds the modeler's memory and time (and says so)
  int max_points = 2000000;
  bool remove_clutter = true;       ///< (past the paper) floating pixels, ground, wires
  double floating_radius_m = 0.02;  ///< floating-pixel removal: neighbourhood radius
  int floating_min_neighbors = 4;   ///< fewer neighbours within the radius: a floating pixel
  double wire_min_length_m = 1.2;   ///< straight thin horizontal runs this long are wires
};

/// @brief The range noise and what is taken off radii for it.
struct NoiseConfig {
  double sigma_m = -1.0;  ///< range noise; negative: estimated from the trunk
  /// Lateral scatter of returns (1 sigma) from the beam footprint: a partly hit beam reports
  /// its range along the beam centre, so thin objects look wider. Subtracted in quadrature with
  /// the range noise from every radius where no radius table applies. Default: 0.63 x the
  /// LMS111 beam radius at the 2 m working range (8 mm + 15 mrad, SICK LMS1xx manual 3.6.2),
  /// calibrated on the sensor model; 0 for an ideal beam.
  double beam_spread_m = 0.012;
  bool derive_parameters = true;  ///< (past the paper) e_t, thresholds from noise and density
  bool correct_bias = true;       ///< (past the paper) radii corrected for noise (and calibration)
};

/// @brief Algorithm 2: clusters, their graph, the trunk path.
struct GraphConfig {
  int points_per_cluster = 3000;   ///< N_c = points / this (paper: ~3000 per cluster)
  double split_error_m = 0.004;    ///< e_t: mean |d - r| of a cluster's cylinder fit that splits it
  double merge_distance_m = 0.05;  ///< d_t: clusters whose centres are closer merge
  int min_cluster_points = 40;     ///< clusters are not split below twice this
  int neighbors = 30;              ///< N: nearest neighbours of the interface point
  double n_low = 0.3;              ///< n_L: lower bound of the neighbour share for an edge
  double n_high = 0.7;             ///< n_H: upper bound
  double psi_t_deg = 72.0;         ///< psi_T: stop the trunk path at edges this far from vertical
  int kmeans_iterations = 30;      ///< Lloyd iterations at most
  bool follow_diameter = true;  ///< (past the paper) trunk top followed by diameter, not the most
                                ///< vertical edge
};

/// @brief RANSAC circle and cylinder fits, shared by the trunk and branch steps.
struct FitConfig {
  double circle_threshold_m = 0.008;    ///< RANSAC inlier band of the slice circles
  double cylinder_threshold_m = 0.012;  ///< RANSAC inlier band of trunk and branch cylinders
  int ransac_iterations = 200;          ///< RANSAC circle iterations
  /// (past the paper) trunk near vertical, radius continuity, branches radial
  bool constrain = true;
};

/// @brief Algorithm 3, trunk part: slices, partitions, segment cylinders.
struct TrunkConfig {
  double slice_height_m = 0.05;        ///< Delta Z (paper: 3-7 cm)
  int disturbance_zero_run = 2;        ///< slices of flat eta before a rise counts as a partition
  double curvature_jump = 0.25;        ///< outlier-share jump along a segment that splits it
  double min_segment_length_m = 0.15;  ///< trunk segments are not split below this
  /// A segment longer than this is cut into equal parts no longer: a trunk tapers and bends
  /// along metres without a disturbance to cut at, and one cylinder over 2-3 m sits
  /// centimetres off the wood and too wide at its top. 0: off (the paper's segments).
  double max_segment_length_m = 0.9;
  /// A segment whose centreline leaves the chord between its ends by more than this is split
  /// where it leaves it most (a leader that wanders off a straight line: one cylinder over the
  /// bend lies centimetres off the wood). 0: off (the paper's segments).
  double max_bend_m = 0.03;
  double max_tilt_deg = 30.0;  ///< trunk cylinders' axes within this of vertical
  /// With noise.correct_bias: segment radii from one smooth taper profile fitted to all slices
  /// (robust to slices through branch bases), not each segment's median slice.
  bool taper_profile = true;
  /// (past the paper) Once the branches are found, the trunk is measured again without the
  /// returns beyond its surface band that lie nearer a found branch's surface (its axis carried
  /// back to the trunk) than the trunk's: slices through a whorl's branch bases read
  /// centimetres wide.
  bool without_branch_bases = true;
  double radius_continuity = 0.35;  ///< a segment's radius within this share of its neighbour's
};

/// @brief Algorithm 3, branch part: candidates, their search, the checks on each fit.
struct BranchConfig {
  /// (past the paper) candidates from all points in a shell around the trunk, validated
  bool shell = true;
  double cluster_tolerance_m = 0.012;  ///< Euclidean clustering of branch candidates
  int min_points = 25;                 ///< smaller clusters are not branches
  double fit_length_m = 0.30;  ///< a branch cylinder covers this much from the trunk surface
  /// Re-clusterings of what is left after a branch is taken out of a candidate cluster, and
  /// halvings of candidates that fit no branch, per tree: a bound on the work. A real tree
  /// needs hundreds (a mature tree lost a third of its branches at 400).
  int search_budget = 4000;
  /// A candidate that fits no branch is first parted along the strongest ray from the trunk
  /// axis through it (a Hough transform: the branches of a whorl fuse near the trunk at
  /// centimetre noise), and only then halved by position.
  bool ray_split = true;
  /// ... from this estimated range noise on: below it the whorl's branches stay apart, and rays
  /// through the clutter of a cloud's few fused candidates pass as branches more often than
  /// they part real ones.
  double ray_split_min_noise_m = 0.008;
  /// A fit whose points start farther than inner_gap_m + 5 cm off the trunk surface is kept
  /// when returns fill its way back to the trunk and part of that way lies off every accepted
  /// branch: at centimetre noise a branch crossing it near the trunk takes its near part out.
  bool keep_cut_off = true;
  /// Two detections that are pieces of one curved branch (one centre inside the other's tube,
  /// axes within 45 deg) are one; the longer is kept. Off: only near-parallel duplicates merge.
  bool merge_curved = true;
  /// What the search turned down is clustered again, once every other branch is out, and
  /// searched for steep branches alone (more than max_radial_angle_deg and at most
  /// max_steep_angle_deg from the radial): steep scaffolds leave the trunk side by side and
  /// fuse into clusters that are not one directed line.
  bool steep_search = true;
  /// A detection with fewer inliers than this fraction of the median over the tree's
  /// detections is dropped (a shoot on a primary, a neighbour's branch tip, a streak of mixed
  /// pixels); 0: off. Needs at least 4 detections.
  double min_relative_points = 0.25;
  double max_radial_angle_deg = 60.0;  ///< branch axis vs the direction away from the trunk
  /// The same bound for a candidate whose points form a long, clearly directed cluster (a
  /// steep scaffold of a central leader leaves more upwards than outwards).
  double max_steep_angle_deg = 75.0;
  /// Branch axis seen along the trunk (elevation removed) vs the direction away from it.
  double max_azimuth_deg = 20.0;
  double min_elevation_deg = -30.0;  ///< above the trunk's normal plane (primaries: >= -20)
  double max_diameter_ratio = 1.0;   ///< a primary is not thicker than the trunk there
  double axis_gap_m = 0.10;          ///< branch axis must pass this close to the trunk surface
  double inner_gap_m = 0.05;         ///< shell candidates start this far out from the trunk surface
  double min_length_m = 0.08;        ///< shorter fits are fragments (a 0.2 m primary shows ~0.1 m)
  double min_height_m = 0.3;         ///< no primary attaches lower above the trunk base
  /// Diagnostic: report branches' raw RMS radius, uncorrected (what calibrate_diameters
  /// measures to build the branch table).
  bool raw_radius = false;
};

/// @brief Every parameter of the tree modeler, by stage (config/tree_modeler.yaml, documented
/// in docs/configuration.md). Defaults are the paper's values (Medeiros et al.,
/// docs/algorithms.md) where the paper tuned one; the switches marked "past the paper" turn on
/// what we add, each separately so its effect can be measured (paper() turns them all off).
struct ModelerConfig {
  PreprocessConfig preprocess;
  NoiseConfig noise;
  GraphConfig graph;
  FitConfig fit;
  TrunkConfig trunk;
  BranchConfig branches;
  /// Branch / trunk diameter above which a branch is a pruning candidate.
  double prune_ratio = 0.5;
  std::uint64_t seed = 1;  ///< k-means++ and RANSAC streams: equal inputs give equal models

  /// The scanner's footprint calibration (calibrate_diameters; loaded from a file by the tools
  /// and the node, not a key of the parameter YAML). Empty (the default): radii are corrected
  /// for range noise alone and the model says so.
  SensorCalibration calibration;
  /// The radius bias the trunk step takes off each slice (apparent minus true, over true radius
  /// and estimated noise): TreeModeler sets it to the noise part (trunkNoiseBias) plus the
  /// calibration's trunk footprint when noise.correct_bias is on. Set by hand only when calling
  /// the stages directly; empty: raw radii.
  RadiusCalibration trunk_calibration;
  /// The same for the branch step's raw RMS radius (branchNoiseBias plus the branch footprint);
  /// empty: the moment less beam_spread_m and noise in quadrature instead.
  RadiusCalibration branch_calibration;

  /// @brief Whether the branch step's radii go through branch_calibration: its own fits
  /// (fit.constrain), corrected (noise.correct_bias), not raw (branches.raw_radius), with a
  /// usable table.
  bool branchTableCorrects() const;

  /// @brief The paper's method alone: every switch past the paper off.
  static ModelerConfig paper();

  /// @brief @throws Error INVALID_ARGUMENT naming the parameter, its value and the valid range.
  void validate() const;
};

/// @brief The keys of ModelerConfig: YAML loading, validation and docs/configuration.md.
const ConfigTable<ModelerConfig>& modelerConfigTable();

/// @brief Load a config from YAML: the `tree_modeler:` map (or the root) of the keys of
/// modelerConfigTable(), groups as nested maps; missing keys keep their defaults, unknown keys
/// are an error, and a key renamed since is named in the error.
/// @throws Error FILE_NOT_FOUND, PARSE_ERROR, INVALID_ARGUMENT
ModelerConfig loadModelerConfig(const std::string& path);

}  // namespace modeling
}  // namespace dormant_tree_modeling
