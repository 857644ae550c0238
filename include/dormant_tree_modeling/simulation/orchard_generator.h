#pragma once

#include <cstdint>
#include <optional>
#include <string>

#include "dormant_tree_modeling/evaluation/ground_truth.h"
#include "dormant_tree_modeling/simulation/scene.h"
#include "dormant_tree_modeling/simulation/tree_generator.h"

namespace dormant_tree_modeling {
namespace simulation {

/// @brief Layout of the orchard around the target tree (m). Defaults follow high-density
/// tall-spindle plantings: 0.9-1.2 m between trees, 3.5 m between rows, 4-5 trellis wires.
struct OrchardConfig {
  std::string preset = "young_tall_spindle";  ///< target and neighbours
  bool neighbours = true;                     ///< one tree on each side in the row
  double neighbour_spacing_min = 0.9;
  double neighbour_spacing_max = 1.2;
  bool other_rows = true;  ///< rows in front and behind, 3 trees each
  double row_spacing = 3.5;
  bool wires = true;
  std::vector<double> wire_heights = {0.6, 1.2, 1.8, 2.4, 3.0};
  double wire_diameter_min = 0.002, wire_diameter_max = 0.004;
  double wire_offset_y = 0.06;  ///< wires run beside the trunks, not through them
  bool post = true;             ///< one post in the row between the target and a neighbour
  bool ground = true;
};

/// @brief A generated scene and the ground truth of its target tree.
struct Orchard {
  Scene scene;
  evaluation::GroundTruth truth;
};

/// @brief Generate the target tree at the origin and its surroundings.
/// @param config layout
/// @param seed equal seeds give equal orchards
/// @throws Error INVALID_ARGUMENT for an unknown preset or inconsistent spacing
Orchard generateOrchard(const OrchardConfig& config, std::uint64_t seed);

/// @brief What the emulators scan, and the target's truth when it is known.
struct SceneAndTruth {
  Scene scene;
  std::optional<evaluation::GroundTruth> truth;
};

/// @brief The scene of a scene file (saveScene) when a path is given, with the truth.json that
/// synth_tree writes beside it if there is one; else the default orchard of the preset and
/// seed, with its truth.
/// @throws Error FILE_NOT_FOUND, PARSE_ERROR, INVALID_ARGUMENT
SceneAndTruth sceneFromFileOrPreset(const std::string& scene_path, const std::string& preset,
                                    std::uint64_t seed);

}  // namespace simulation
}  // namespace dormant_tree_modeling
