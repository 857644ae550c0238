#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/yaml_map.h"
#include "dormant_tree_modeling/registration/multi_view.h"

namespace dormant_tree_modeling {
namespace registration {

// One key per line, as in config/registration.yaml; issue #26 step 4 replaces it with a field
// table shared with the modeler's configuration.
RegistrationConfig loadRegistrationConfig(const std::string& path) {
  RegistrationConfig c;
  forEachYamlEntry(
      path, "registration", "registration parameter",
      [&c, &path](const std::string& key, const YAML::Node& v) {
        if (key == "icp_voxels")
          c.icp.voxels = v.as<std::vector<double>>();
        else if (key == "icp_distance_factor")
          c.icp.distance_factor = v.as<double>();
        else if (key == "icp_max_iterations")
          c.icp.max_iterations = v.as<int>();
        else if (key == "icp_trim")
          c.icp.trim = v.as<double>();
        else if (key == "icp_huber")
          c.icp.huber = v.as<double>();
        else if (key == "icp_normal_neighbors")
          c.icp.normal_neighbors = v.as<int>();
        else if (key == "icp_across_cos")
          c.icp.across_cos = v.as<double>();
        else if (key == "icp_overlap_distance")
          c.icp.overlap_distance = v.as<double>();
        else if (key == "icp_min_rotation_step")
          c.icp.min_rotation_step = v.as<double>();
        else if (key == "icp_min_translation_step")
          c.icp.min_translation_step = v.as<double>();
        else if (key == "icp_axis_pairs")
          c.icp.axis_pairs = v.as<bool>();
        else if (key == "icp_axis_max_angle_deg")
          c.icp.axis_max_angle_deg = v.as<double>();
        else if (key == "axis_patch")
          c.axes.patch = v.as<double>();
        else if (key == "axis_min_points")
          c.axes.min_points = v.as<int>();
        else if (key == "axis_linearity")
          c.axes.linearity = v.as<double>();
        else if (key == "axis_max_view_cos")
          c.axes.max_view_cos = v.as<double>();
        else if (key == "axis_min_view_agreement")
          c.axes.min_view_agreement = v.as<double>();
        else if (key == "axis_min_radius")
          c.axes.min_radius = v.as<double>();
        else if (key == "axis_max_radius")
          c.axes.max_radius = v.as<double>();
        else if (key == "beam_exit" || key == "beam_divergence" || key == "silhouette_fraction")
          throw Error(ErrorCode::PARSE_ERROR,
                      path + ": '" + key +
                          "' is no longer a registration parameter: the "
                          "silhouette growth comes from the sensor calibration "
                          "file (calibrate_diameters --scan RIG_VIEWS_DIR)");
        else if (key == "coarse_cell")
          c.coarse.cell = v.as<double>();
        else if (key == "coarse_yaw_window_deg")
          c.coarse.yaw_window_deg = v.as<double>();
        else if (key == "coarse_yaw_step_deg")
          c.coarse.yaw_step_deg = v.as<double>();
        else if (key == "coarse_xy_window")
          c.coarse.xy_window = v.as<double>();
        else if (key == "coarse_z_window")
          c.coarse.z_window = v.as<double>();
        else if (key == "coarse_z_window_unhinted")
          c.coarse.z_window_unhinted = v.as<double>();
        else if (key == "coarse_z_step")
          c.coarse.z_step = v.as<double>();
        else if (key == "coarse_candidates")
          c.coarse.candidates = v.as<int>();
        else if (key == "candidate_levels")
          c.candidate_levels = v.as<int>();
        else if (key == "refinement_rounds")
          c.refinement_rounds = v.as<int>();
        else if (key == "min_points")
          c.min_points = v.as<std::size_t>();
        else if (key == "min_overlap")
          c.min_overlap = v.as<double>();
        else if (key == "max_rmse")
          c.max_rmse = v.as<double>();
        else if (key == "use_hints")
          c.use_hints = v.as<bool>();
        else
          return false;
        return true;
      });
  c.validate();
  return c;
}

bool applySensorCalibration(const modeling::SensorCalibration& calibration,
                            RegistrationConfig& config) {
  if (!calibration.silhouette.measured)
    return false;
  const auto& s = calibration.silhouette;
  config.axes.silhouette_growth_m = s.depth_share * s.growth_m;
  config.axes.silhouette_growth_per_m = s.depth_share * s.growth_per_m;
  return true;
}

}  // namespace registration
}  // namespace dormant_tree_modeling
