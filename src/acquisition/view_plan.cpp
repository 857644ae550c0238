#include "dormant_tree_modeling/acquisition/view_plan.h"

#include <cmath>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/yaml_map.h"
#include "dormant_tree_modeling/geometry/stage_kinematics.h"

namespace dormant_tree_modeling {
namespace acquisition {

namespace {
void require(bool ok, const std::string& what) {
  if (!ok)
    throw Error(ErrorCode::INVALID_ARGUMENT, "view plan: " + what);
}
}  // namespace

int ViewPlanConfig::linesPerView() const {
  return static_cast<int>(std::lround((theta_max_deg - theta_min_deg) / theta_step_deg));
}

void ViewPlanConfig::validate() const {
  require(!heights.empty(), "heights must not be empty");
  for (const double h : heights)
    require(h > 0.0 && h < 10.0, "heights must be in (0, 10) m");
  require(positions_per_height >= 1, "positions_per_height must be >= 1");
  require(position_spacing >= 0.0, "position_spacing must be >= 0");
  require(slide_steps >= 1, "slide_steps must be >= 1");
  require(slide_step >= 0.0 && slide_step * (slide_steps - 1) <= 2.0,
          "slide_step must be >= 0 and the slide travel at most 2 m");
  require(standoff > 0.5, "standoff must be > 0.5 m (the LMS111 minimum range)");
  require(front || back, "at least one of front/back");
  require(theta_min_deg < theta_max_deg && theta_min_deg >= -180.0 && theta_max_deg <= 180.0,
          "need -180 <= theta_min_deg < theta_max_deg <= 180");
  require(theta_step_deg > 0.0 && linesPerView() >= 1, "theta_step_deg must be > 0");
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
    const double y = is_front ? -config.standoff : config.standoff;
    for (const double h : config.heights) {
      for (int p = 0; p < config.positions_per_height; ++p) {
        const double x = (p - 0.5 * (config.positions_per_height - 1)) * config.position_spacing;
        for (int s = 0; s < config.slide_steps; ++s) {
          PlannedView v;
          v.index = static_cast<int>(views.size());
          v.platform_index = platform_index;
          v.side = is_front ? "front" : "back";
          v.platform = geometry::platformPose(x, y, h, yaw);
          v.slide = (s - 0.5 * (config.slide_steps - 1)) * config.slide_step;
          views.push_back(v);
        }
        ++platform_index;
      }
    }
  }
  return views;
}

ViewPlanConfig loadViewPlan(const std::string& path) {
  ViewPlanConfig c;
  forEachYamlEntry(path, "", "view plan key", [&c](const std::string& key, const YAML::Node& v) {
    if (key == "heights")
      c.heights = v.as<std::vector<double>>();
    else if (key == "positions_per_height")
      c.positions_per_height = v.as<int>();
    else if (key == "position_spacing")
      c.position_spacing = v.as<double>();
    else if (key == "slide_steps")
      c.slide_steps = v.as<int>();
    else if (key == "slide_step")
      c.slide_step = v.as<double>();
    else if (key == "standoff")
      c.standoff = v.as<double>();
    else if (key == "front")
      c.front = v.as<bool>();
    else if (key == "back")
      c.back = v.as<bool>();
    else if (key == "theta_min_deg")
      c.theta_min_deg = v.as<double>();
    else if (key == "theta_max_deg")
      c.theta_max_deg = v.as<double>();
    else if (key == "theta_step_deg")
      c.theta_step_deg = v.as<double>();
    else
      return false;
    return true;
  });
  c.validate();
  return c;
}

}  // namespace acquisition
}  // namespace dormant_tree_modeling
