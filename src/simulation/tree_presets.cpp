#include <optional>
#include <string>
#include <vector>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/simulation/tree_generator.h"

namespace dormant_tree_modeling {
namespace simulation {

std::vector<std::string> presetNames() {
  return {"young_tall_spindle", "mature_tall_spindle", "central_leader"};
}

std::vector<std::string> variantPresetNames() {
  return {"crooked_leader", "drooping_scaffolds", "steep_scaffolds", "sparse_whorls",
          "dense_whorls"};
}

namespace {

/// Trees the modeler is only scored on: the young tall spindle with one trait pushed.
std::optional<TreeConfig> variantParams(const std::string& name) {
  TreeConfig p;
  p.preset = name;
  if (name == "crooked_leader") {
    p.bend_amplitude_max = 0.15;  // the leader sways up to 15 cm off its line
    p.lean_max_deg = 10.0;
    return p;
  }
  if (name == "drooping_scaffolds") {
    p.droop_deg_per_m = 70.0;
    p.branch_length_min = 0.5;
    p.branch_length_max = 1.3;
    return p;
  }
  if (name == "steep_scaffolds") {
    p.elevation_min_deg = 30.0;
    p.elevation_max_deg = 70.0;
    p.branch_length_min = 0.6;
    p.branch_length_max = 1.4;
    p.droop_deg_per_m = 5.0;
    return p;
  }
  if (name == "sparse_whorls") {
    p.primaries_min = 6;
    p.primaries_max = 10;
    return p;
  }
  if (name == "dense_whorls") {
    p.primaries_min = 45;
    p.primaries_max = 60;
    return p;
  }
  return std::nullopt;
}

}  // namespace

TreeConfig presetParams(const std::string& name) {
  TreeConfig p;
  p.preset = name;
  if (name == "young_tall_spindle") {
    return p;  // the struct defaults describe it
  }
  if (name == "mature_tall_spindle") {
    p.height_min = 3.0;
    p.height_max = 4.0;
    p.base_diameter_min = 0.07;
    p.base_diameter_max = 0.11;
    p.top_diameter = 0.018;
    p.primaries_min = 20;
    p.primaries_max = 35;
    p.primary_diameter_min = 0.010;
    p.primary_diameter_max = 0.040;
    p.first_branch_min = 0.55;
    p.first_branch_max = 0.85;
    p.branch_length_min = 0.35;
    p.branch_length_max = 1.1;
    p.secondaries_per_m = 4.0;
    p.spurs_per_m = 6.0;
    return p;
  }
  if (name == "central_leader") {
    p.height_min = 3.0;
    p.height_max = 4.5;
    p.base_diameter_min = 0.10;
    p.base_diameter_max = 0.20;
    p.top_diameter = 0.025;
    p.lean_max_deg = 8.0;
    p.bend_amplitude_max = 0.08;
    p.primaries_min = 6;
    p.primaries_max = 15;
    p.primary_diameter_min = 0.03;
    p.primary_diameter_max = 0.08;
    p.ratio_min = 0.3;
    p.ratio_max = 0.6;
    p.first_branch_min = 0.6;
    p.first_branch_max = 1.0;
    p.top_branch_fraction = 0.8;
    p.branch_length_min = 0.8;
    p.branch_length_max = 1.8;
    p.elevation_min_deg = 10.0;
    p.elevation_max_deg = 45.0;
    p.droop_deg_per_m = 20.0;
    p.tip_diameter = 0.006;
    p.secondaries_per_m = 3.0;
    p.spurs_per_m = 3.0;
    return p;
  }
  if (const auto v = variantParams(name))
    return *v;
  std::string names;
  for (const auto& n : presetNames())
    names += (names.empty() ? "" : ", ") + n;
  for (const auto& n : variantPresetNames())
    names += ", " + n;
  throw Error(ErrorCode::INVALID_ARGUMENT,
              "unknown tree preset '" + name + "' (known: " + names + ")");
}

}  // namespace simulation
}  // namespace dormant_tree_modeling
