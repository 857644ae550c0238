#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "dormant_tree_modeling/evaluation/ground_truth.h"
#include "dormant_tree_modeling/simulation/scene.h"

namespace dormant_tree_modeling {
namespace simulation {

/// @brief Shape parameters of a generated tree; every range is sampled uniformly per tree or
/// per branch. Lengths in m, diameters in m, angles in degrees.
struct TreeConfig {
  std::string preset;
  double height_min = 2.5, height_max = 4.0;                  ///< leader length
  double base_diameter_min = 0.04, base_diameter_max = 0.08;  ///< trunk at the ground
  double top_diameter = 0.015;                                ///< leader tip
  double lean_max_deg = 10.0;                                 ///< whole-trunk lean
  double bend_amplitude_max = 0.05;  ///< lateral sway of the centreline (curvature)
  int primaries_min = 15, primaries_max = 40;
  double primary_diameter_min = 0.008, primary_diameter_max = 0.035;
  double ratio_min = 0.25, ratio_max = 0.55;  ///< branch / local trunk diameter, common case
  double large_ratio_fraction = 0.2;          ///< share of branches with ratio 0.55..0.8
  double first_branch_min = 0.5, first_branch_max = 0.8;  ///< height of the lowest primary
  double top_branch_fraction = 0.92;                      ///< highest primary at this * height
  double branch_length_min = 0.25, branch_length_max = 1.0;
  double elevation_min_deg = -20.0, elevation_max_deg = 45.0;  ///< at the base, + is upwards
  double droop_deg_per_m = 25.0;   ///< how fast a branch bends down along its length
  double tip_diameter = 0.003;     ///< branch tips
  double secondaries_per_m = 3.0;  ///< lateral shoots on a primary
  double spurs_per_m = 4.0;        ///< short fruiting spurs on a primary
  int trunk_shoots_min = 2, trunk_shoots_max = 6;  ///< thin shoots and stubs on the trunk
  double segment_length = 0.05;                    ///< polyline step
};

/// @brief Named presets: "young_tall_spindle", "mature_tall_spindle", "central_leader".
/// @throws Error INVALID_ARGUMENT for an unknown name (the message lists the names)
TreeConfig presetParams(const std::string& name);

/// @brief The names presetParams() accepts.
std::vector<std::string> presetNames();

/// @brief Tree variants for scoring only (never tuned on): the young tall spindle with a
/// crooked leader, drooping or long steep scaffolds, sparse or dense whorls.
std::vector<std::string> variantPresetNames();

/// @brief Generate one dormant tree whose trunk starts at `base` on the ground.
/// @param params shape ranges
/// @param seed equal seeds give equal trees
/// @param base trunk base position (m)
/// @param azimuth_offset rotates the branch layout (rad), so neighbours differ from the target
TreeObject generateTree(const TreeConfig& params, std::uint64_t seed, const Eigen::Vector3d& base,
                        double azimuth_offset = 0.0);

/// @brief Ground truth of a generated tree (docs/evaluation.md): the trunk polyline, every
/// PRIMARY polyline as a primary branch, every MINOR one as a minor branch.
evaluation::GroundTruth truthFromTree(const TreeObject& tree);

/// @brief Primary-branch definition of docs/evaluation.md.
constexpr double PRIMARY_MIN_BASE_DIAMETER = 0.008;  ///< m
constexpr double PRIMARY_MIN_LENGTH = 0.2;           ///< m

}  // namespace simulation
}  // namespace dormant_tree_modeling
