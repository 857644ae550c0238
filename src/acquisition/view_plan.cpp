#include "dormant_tree_modeling/acquisition/view_plan.h"

#include <cmath>

#include "dormant_tree_modeling/common/config_table.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/geometry/stage_kinematics.h"

namespace dormant_tree_modeling {
namespace acquisition {

namespace {
ConfigTable<ViewPlanConfig> makeTable() {
  using V = ViewPlanConfig;
  ConfigTable<V> t("view plan parameter", "");
  t.add("heights_m", &V::heights_m, 0.1, 10.0, "Laser heights above the ground.")
      .formerly("heights")
      .add("positions_per_height", &V::positions_per_height, 1, 100,
           "Platform positions along the row at each height.")
      .add("position_spacing_m", &V::position_spacing_m, 0.0, 10.0,
           "Between platform positions, along the row.")
      .formerly("position_spacing")
      .add("slide_steps", &V::slide_steps, 1, 1000, "Views per platform position.")
      .add("slide_step_m", &V::slide_step_m, 0.0, 2.0,
           "Slide move between views, centred on the slide; the travel is at most 2 m.")
      .formerly("slide_step")
      .add("standoff_m", &V::standoff_m, 0.5, 20.0,
           "Horizontal distance from the row to the rotation axis (the LMS111 sees from 0.5 m).")
      .formerly("standoff")
      .add("front", &V::front, "Scan from the front (y < 0).")
      .add("back", &V::back, "Scan from the back (y > 0).")
      .add("theta_min_deg", &V::theta_min_deg, -180.0, 180.0,
           "Rotary sweep: theta_min_deg <= theta < theta_max_deg.")
      .add("theta_max_deg", &V::theta_max_deg, -180.0, 180.0, "End of the rotary sweep.")
      .add("theta_step_deg", &V::theta_step_deg, 0.01, 90.0,
           "One scan line per step (0.45: 200 lines).");
  return t;
}

}  // namespace

int ViewPlanConfig::linesPerView() const {
  return static_cast<int>(std::lround((theta_max_deg - theta_min_deg) / theta_step_deg));
}

void ViewPlanConfig::validate() const {
  viewPlanConfigTable().check(*this);
  viewPlanConfigTable().require(slide_step_m * (slide_steps - 1) <= 2.0,
                                "the slide travel must be at most 2 m");
  viewPlanConfigTable().require(front || back, "at least one of front/back");
  viewPlanConfigTable().require(theta_min_deg < theta_max_deg,
                                "theta_min_deg must be below theta_max_deg");
  viewPlanConfigTable().require(linesPerView() >= 1,
                                "the sweep must hold at least one theta_step_deg");
}

std::vector<PlannedView> makeViewPlan(const ViewPlanConfig& config) {
  config.validate();
  std::vector<PlannedView> views;
  int platform_index = 0;
  for (const bool is_front : {true, false}) {
    if ((is_front && !config.front) || (!is_front && !config.back))
      continue;
    // Facing the tree: from the front the platform's x points to +y, from the back to -y.
    const double yaw = is_front ? M_PI / 2.0 : -M_PI / 2.0;
    const double y = is_front ? -config.standoff_m : config.standoff_m;
    for (const double h : config.heights_m) {
      for (int p = 0; p < config.positions_per_height; ++p) {
        const double x = (p - 0.5 * (config.positions_per_height - 1)) * config.position_spacing_m;
        for (int s = 0; s < config.slide_steps; ++s) {
          PlannedView v;
          v.index = static_cast<int>(views.size());
          v.platform_index = platform_index;
          v.side = is_front ? "front" : "back";
          v.platform = geometry::platformPose(x, y, h, yaw);
          v.slide = (s - 0.5 * (config.slide_steps - 1)) * config.slide_step_m;
          views.push_back(v);
        }
        ++platform_index;
      }
    }
  }
  return views;
}

const ConfigTable<ViewPlanConfig>& viewPlanConfigTable() {
  static const ConfigTable<ViewPlanConfig> table = makeTable();
  return table;
}

ViewPlanConfig loadViewPlan(const std::string& path) {
  ViewPlanConfig c;
  viewPlanConfigTable().load(path, c);
  c.validate();
  return c;
}

}  // namespace acquisition
}  // namespace dormant_tree_modeling
