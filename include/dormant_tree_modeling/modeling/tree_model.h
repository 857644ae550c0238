#pragma once

#include <Eigen/Core>
#include <Eigen/Geometry>
#include <cstddef>
#include <string>
#include <vector>

namespace dormant_tree_modeling {
namespace modeling {

/// @brief The least radius a primary branch is given (m): the fits search no thinner, and a
/// noise correction that would take a radius below it stops there.
constexpr double MIN_BRANCH_RADIUS_M = 0.002;

/// @brief One fitted cylinder (trunk segment or primary branch), in metres.
struct CylinderModel {
  int id = 0;                                        ///< unique within one TreeModel
  Eigen::Vector3d center = Eigen::Vector3d::Zero();  ///< middle of the axis segment
  Eigen::Vector3d axis = Eigen::Vector3d::UnitZ();   ///< unit; trunk upwards, branch outwards
  double diameter = 0.0;                             ///< m
  double length = 0.0;                               ///< m, along the axis
  std::size_t num_points = 0;                        ///< inliers supporting the fit
  double inlier_ratio = 0.0;                         ///< inliers / segment points, 0..1
};

/// @brief Measurements of one primary branch that pruning decisions use.
struct BranchMeasurement {
  double attachment_height = 0.0;  ///< m above the lowest trunk point
  double angle_to_trunk = 0.0;     ///< rad between branch axis and local trunk axis
  double trunk_diameter = 0.0;     ///< m, trunk diameter at the attachment
  double diameter_ratio = 0.0;     ///< branch diameter / trunk_diameter
  bool prune = false;              ///< diameter_ratio above the configured limit
  /// False when the radius was taken to its floor (MIN_BRANCH_RADIUS_M), where the noise the
  /// modeler corrected for is as wide as the branch, or when its reading is one that thinner
  /// branches give too (RadiusCalibration::resolves): its diameter was not measured and the
  /// diameter, ratio and prune flag carry no information about it.
  bool diameter_resolved = true;
  /// m, the narrowest and widest diameters the branch may have: both its diameter where it was
  /// measured; where not, the floor (2 MIN_BRANCH_RADIUS_M) and the widest diameter the branch
  /// table cannot tell from it (RadiusCalibration::floorAmbiguity at the tree's noise). Where
  /// diameter_max / trunk_diameter is at most the prune ratio, the branch is to be kept
  /// whichever diameter it has.
  double diameter_min = 0.0;
  double diameter_max = 0.0;
};

/// @brief A primary branch: its cylinder, the trunk cylinder it leaves, and its measurements.
struct PrimaryBranch {
  CylinderModel cylinder;
  int trunk_segment = -1;  ///< id of the trunk cylinder the branch leaves
  BranchMeasurement measurement;
};

/// @brief How the model's diameters were corrected for the scanner.
struct DiameterCorrection {
  std::string calibration;       ///< the sensor calibration's name; empty: none was given
  std::string calibration_hash;  ///< of its file (SensorCalibration::hash)
  double noise_sigma = 0.0;      ///< m, the range noise the modeler estimated (or was given)
  /// m, that estimate as the radius tables read it: what 5 cm slices would read for the same
  /// noise (standardNoiseReading; with a calibration through its rig's readings)
  double table_noise_sigma = 0.0;
  /// m, the scatter about every trunk slice circle, whorls included, which the branch search's
  /// noise gates take (TrunkModel::search_sigma)
  double search_noise_sigma = 0.0;
  /// Each said once: no calibration (noise part only), or the tree needing the tables outside
  /// the radii or noise the calibration's rig covered.
  std::vector<std::string> warnings;
};

/// @brief The model of one tree (docs/evaluation.md "model.json").
struct TreeModel {
  std::size_t input_points = 0;
  std::vector<CylinderModel> trunk;  ///< bottom to top
  std::vector<PrimaryBranch> primary_branches;
  double runtime_s = 0.0;  ///< wall time of the modeler, s
  DiameterCorrection correction;
};

/// @brief The model in another frame: centres moved, axes rotated by `pose` (a rigid
/// transform, e.g. a tree frame into the orchard frame); sizes and measurements unchanged.
TreeModel transformModel(const TreeModel& model, const Eigen::Isometry3d& pose);

}  // namespace modeling
}  // namespace dormant_tree_modeling
