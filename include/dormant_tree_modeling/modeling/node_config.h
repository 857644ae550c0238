#pragma once

#include <string>

namespace dormant_tree_modeling {

template <typename Config>
class ConfigTable;

namespace modeling {

/// @brief The tree modeler node's parameters (launch/tree_modeler.launch); the modeler's own
/// come from config_file.
struct TreeModelerNodeConfig {
  std::string config_file;       ///< modeler parameters (config/tree_modeler.yaml); empty: defaults
  std::string calibration_file;  ///< sensor calibration; empty: the noise part only (warned)
  std::string output_dir;        ///< model.json and cylinders.csv per model; empty: none
  std::string output_frame;      ///< cylinders published in this frame; empty: the cloud's
  int exit_after_models = 0;     ///< shut down after this many models; 0: run on
};

/// @brief The keys of the tree modeler node: its parameters, docs/configuration.md.
const ConfigTable<TreeModelerNodeConfig>& treeModelerNodeConfigTable();

}  // namespace modeling
}  // namespace dormant_tree_modeling
