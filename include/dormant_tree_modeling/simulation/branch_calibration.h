#pragma once

#include "dormant_tree_modeling/simulation/trunk_calibration.h"

namespace dormant_tree_modeling {
namespace simulation {

/// @brief The branch radius calibration: a reference tree (a pole with straight rods of known
/// radii at many heights, azimuths and angles) scanned with the view plan at each noise level
/// and modeled by the whole modeler with no branch calibration; each detected rod's apparent
/// radius (the RMS distance of its points from its axis, which the beam footprint and the
/// noise dominate for thin branches) is tabulated against its true radius. `options.radii`
/// are the rod radii.
/// @throws Error INVALID_ARGUMENT for empty or non-ascending radii or noise
TrunkCalibrationResult calibrateBranchRadii(const TrunkCalibrationOptions& options);

/// @brief Rod radii of the default branch calibration (m).
std::vector<double> defaultBranchCalibrationRadii();

}  // namespace simulation
}  // namespace dormant_tree_modeling
