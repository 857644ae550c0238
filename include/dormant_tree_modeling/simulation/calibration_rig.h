#pragma once

#include <cstdint>
#include <string>

#include "dormant_tree_modeling/simulation/orchard_generator.h"

namespace dormant_tree_modeling {
namespace simulation {

/// @brief Name of the rig in OrchardConfig::preset and `synth_tree --preset`.
constexpr const char* CALIBRATION_RIG_PRESET = "calibration_rig";

/// @brief The reference rig that `calibrate_diameters` measures, as a user would build it:
/// a vertical pipe of stepped sections (200, 140, 100, 60, 40, 25 and 16 mm: apple trunks and
/// leaders) with straight rods of 4 to 40 mm (primaries and their thin ends), two of each, leaving
/// the 60 mm section at 0, 20 and 35 deg elevation a golden angle apart, on bare ground. Its truth
/// (the RIG.json of calibrate_diameters) has the pipe as `trunk` (constant-diameter sections joined
/// by 2 mm steps) and the rods as `primary_branches`.
/// @param seed turns the rig about its axis (where the rods point)
Orchard calibrationRig(std::uint64_t seed);

}  // namespace simulation
}  // namespace dormant_tree_modeling
