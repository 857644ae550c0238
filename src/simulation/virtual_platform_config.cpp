#include "dormant_tree_modeling/common/config_table.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/simulation/virtual_platform.h"

namespace dormant_tree_modeling {
namespace simulation {

namespace {

ConfigTable<VirtualPlatformNodeConfig> makeTable() {
  using V = VirtualPlatformNodeConfig;
  ConfigTable<V> t("virtual platform parameter", "");
  t.add("lms_port", &V::lms_port, -1, 65535, "The emulated LMS111's CoLa-A port; 0: any, -1: off.")
      .add("lms_b_port", &V::lms_b_port, -1, 65535, "Its CoLa-B port.")
      .add("aerotech_port", &V::aerotech_port, -1, 65535, "The emulated Ensemble's port.")
      .add("scan_frequency_hz", &V::scan_frequency_hz, 25.0, 50.0,
           "The LMS111's power-up scan frequency (25 or 50).")
      .formerly("frequency")
      .add("noise_mm", &V::noise_mm, 0.0, 100.0, "Range noise, 1 sigma.")
      .add("seed", &V::seed, 0, 2147483647, "Scene, sensor noise and operator error streams.")
      .add("platform", &V::platform, -1000.0, 1000.0,
           "Start pose [x_m, y_m, z_m, yaw_deg] in the scene frame.")
      .add("fault_axis", &V::fault_axis, "The emulated stage fails moves of this axis ...")
      .add("fault_on_move", &V::fault_on_move, 0, 1000000, "... from this move on; 0: never.")
      .add("scene_frame", &V::scene_frame, "Frame of the scene and the platform pose.")
      .add("output_dir", &V::output_dir, "scene.json and truth.json go here; empty: nowhere.")
      .add("in_place_service", &V::in_place_service, "Called when the platform reached a goal.")
      .add("placement_error_m", &V::placement_error_m, 0.0, 2.0,
           "The virtual operator's error after the first position.")
      .formerly("placement_error")
      .add("placement_error_yaw_deg", &V::placement_error_yaw_deg, 0.0, 180.0, "... in heading.")
      .formerly("placement_error_yaw")
      .add("settle_time_s", &V::settle_time_s, 0.0, 60.0,
           "After a move before the platform reports it is in place.")
      .formerly("settle_time")
      .add("scene_file", &V::scene_file, "A scene.json (synth_tree); empty: the preset.")
      .add("preset", &V::preset, "Tree preset (synth_tree --help lists them).")
      .add("follow_goals", &V::follow_goals, "Drive to the acquisition's platform goals.")
      .add("goal_topic", &V::goal_topic, "Where the goals come from.");
  return t;
}

}  // namespace

const ConfigTable<VirtualPlatformNodeConfig>& virtualPlatformNodeConfigTable() {
  static const ConfigTable<VirtualPlatformNodeConfig> table = makeTable();
  return table;
}

void VirtualPlatformNodeConfig::validate() const {
  virtualPlatformNodeConfigTable().check(*this);
  if (platform.size() != 4)
    throw Error(ErrorCode::INVALID_ARGUMENT,
                "virtual platform parameter platform takes [x_m, y_m, z_m, yaw_deg]");
}

}  // namespace simulation
}  // namespace dormant_tree_modeling
