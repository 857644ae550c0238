#include "dormant_tree_modeling/modeling/node_config.h"

#include "dormant_tree_modeling/common/config_table.h"

namespace dormant_tree_modeling {
namespace modeling {

namespace {

ConfigTable<TreeModelerNodeConfig> makeTable() {
  using N = TreeModelerNodeConfig;
  ConfigTable<N> t("tree modeler node parameter", "");
  t.add("config_file", &N::config_file,
        "Modeler parameters (config/tree_modeler.yaml); empty: the defaults.")
      .add("calibration_file", &N::calibration_file,
           "Sensor calibration (calibrate_diameters); empty: diameters corrected for range "
           "noise only (warned).")
      .add("output_dir", &N::output_dir,
           "model.json, cylinders.csv, turned_down.csv and cloud.pcd/.ply of each model; empty: "
           "none.")
      .add("output_frame", &N::output_frame,
           "Cylinders and segments published in this frame; empty: the cloud's.")
      .add("exit_after_models", &N::exit_after_models, 0, 1000000,
           "Shut down after this many models (replay); 0: run on.");
  return t;
}

}  // namespace

const ConfigTable<TreeModelerNodeConfig>& treeModelerNodeConfigTable() {
  static const ConfigTable<TreeModelerNodeConfig> table = makeTable();
  return table;
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
