#pragma once

#include <string>
#include <vector>

#include "dormant_tree_modeling/evaluation/ground_truth.h"
#include "dormant_tree_modeling/modeling/geometry_fit.h"
#include "dormant_tree_modeling/modeling/modeler_config.h"
#include "dormant_tree_modeling/modeling/sensor_calibration.h"
#include "dormant_tree_modeling/registration/multi_view.h"

namespace dormant_tree_modeling {
namespace calibration {

/// @brief One scan of the reference rig and what is known of it (RIG.json, the truth schema of
/// docs/evaluation.md: the pipe as `trunk`, constant-diameter sections between pairs of
/// points; the rods as `primary_branches`). Diameters exact, axes within a few cm, in the
/// scan's frame (survey coordinates too).
struct RigScan {
  std::string name;  ///< for messages and the calibration's sources
  modeling::Points points;
  evaluation::GroundTruth rig;
  /// The views the scan was merged from, each with its pose into the rig's frame as
  /// `in_station` (optional): with them the silhouette growth of the registration's branch
  /// axes is measured on the rods, each station's side apart.
  std::vector<registration::ViewInput> views;
};

/// @brief A rig scan from a folder of views (views.json, views/<name>.pcd): each view put
/// into the rig's frame by its `true_pose` in views.json or, without one, by its pose in the
/// folder's registration.json (register_views' output, copied there).
/// @throws Error FILE_NOT_FOUND, PARSE_ERROR; INVALID_ARGUMENT when a view has no pose
RigScan readRigViews(const std::string& dir, const evaluation::GroundTruth& rig);

/// @brief One measured pipe section or rod.
struct RigSample {
  std::string scan;
  bool trunk = false;       ///< pipe section (trunk step), else rod (branch step)
  int index = 0;            ///< section number from the bottom, or rod id
  double radius = 0.0;      ///< true (m)
  double apparent = 0.0;    ///< the modeler's raw radius (m)
  double noise = 0.0;       ///< the modeler's noise estimate on that scan (m)
  double noise_part = 0.0;  ///< what the noise alone explains (m)
  /// apparent - radius - noise_part: the footprint's share (m)
  double footprint() const { return apparent - radius - noise_part; }
};

/// @brief Up to which true radius a branch cannot be told from the modeler's floor, at one
/// noise row of a calibration (RadiusCalibration::floorAmbiguity of its branch table).
struct FloorReach {
  double noise_m = 0.0;   ///< the row's noise reading
  double radius_m = 0.0;  ///< the largest true radius that some thinner one reads alike
};

/// @brief A calibration and how it was made.
struct RigCalibrationResult {
  modeling::SensorCalibration calibration;
  std::vector<RigSample> samples;
  std::vector<FloorReach> branch_floor_reach;  ///< one per noise row, ascending noise
  std::vector<std::string> warnings;           ///< rods or sections not found, narrow coverage
};

/// @brief How the rig's parts are searched for around the axes RIG.json gives.
struct RigSearch {
  double axis_tolerance_m = 0.08;  ///< a rod or section this far from its stated axis is found
  double section_margin_m = 0.06;  ///< left out at each end of a pipe section (steps, rods)
  int min_slices = 3;              ///< slice circles a section needs to be measured
  /// A silhouette sample belongs to a rod when its axis point lies this close to the rod's
  /// axis and its direction within max_silhouette_angle_deg of the rod's.
  double silhouette_reach_m = 0.02;
  double max_silhouette_angle_deg = 20.0;
  int min_silhouette_samples = 20;  ///< fewer: the silhouette is not measured (warned)
};

/// @brief One branch-axis sample of the registration's estimator on a rig rod (m).
struct SilhouetteSample {
  double range = 0.0;        ///< the sample's patch from its sensor
  double width = 0.0;        ///< the silhouette's width (twice the radius with no growth taken)
  double diameter = 0.0;     ///< the rod's true diameter
  double depth_error = 0.0;  ///< of the sample's axis point, signed, towards the sensor
};

/// @brief The silhouette model width = diameter_gain x diameter + growth_m + growth_per_m x
/// range by least squares, refitted without the samples beyond 2.5 robust sigmas of the first
/// fit. growth_per_m is 0 when the ranges spread less than 0.2 m and the gain is 1 when the
/// diameters spread less than 2 mm (standard deviations); a gain outside
/// [MIN_DIAMETER_GAIN, MAX_DIAMETER_GAIN] is held at the bound with a warning and the margin
/// refitted for it. depth_share is left at 1 (calibrateFromRig bisects it on the rods).
/// @param warnings receives what was held
/// @throws Error EMPTY_INPUT when there are no samples
modeling::SensorCalibration::Silhouette fitSilhouette(const std::vector<SilhouetteSample>& samples,
                                                      std::vector<std::string>* warnings);

/// @brief Measure every rod and pipe section of the rig in each scan with the modeler's own
/// estimators (the trunk step's slice circles, the branch step's raw radius) and its noise
/// estimate, take off the noise part (noise_bias.h) and tabulate the rest, the footprint, over
/// the true radius: one row per scan's noise, monotone (non-increasing) in the radius.
/// @param config the modeler's parameters (its calibration is ignored)
/// @param name the calibration's name
/// @throws Error EMPTY_INPUT for a scan without points, NO_TRUNK when a scan shows no pipe
///         section or no rod of its rig, INVALID_ARGUMENT for a rig without sections or rods
RigCalibrationResult calibrateFromRig(const std::vector<RigScan>& scans,
                                      const modeling::ModelerConfig& config,
                                      const std::string& name, const RigSearch& search = {});

}  // namespace calibration
}  // namespace dormant_tree_modeling
