#include "dormant_tree_modeling/modeling/modeler_config.h"

#include <functional>
#include <map>
#include <sstream>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/yaml_map.h"

namespace dormant_tree_modeling {
namespace modeling {

namespace {

template <typename T>
void check(const char* name, T value, T lo, T hi) {
  if (!(value >= lo && value <= hi)) {
    std::ostringstream s;
    s << "tree modeler parameter " << name << " = " << value << " is outside [" << lo << ", " << hi
      << "]";
    throw Error(ErrorCode::INVALID_ARGUMENT, s.str());
  }
}

void checkCalibration(const std::string& name, const RadiusCalibration& cal) {
  if (cal.radii.empty() && cal.noise.empty() && cal.bias.empty())
    return;  // no table: no correction
  if (!cal.valid()) {
    throw Error(ErrorCode::INVALID_ARGUMENT,
                "tree modeler parameters " + name +
                    "_*: radii and noise must be ascending and non-empty, bias must hold noise x "
                    "radii = " +
                    std::to_string(cal.noise.size() * cal.radii.size()) + " values (has " +
                    std::to_string(cal.bias.size()) + ")");
  }
  for (const double b : cal.bias)
    check((name + "_bias").c_str(), b, -0.05, 0.05);
  check((name + "_radii").c_str(), cal.radii.front(), 1e-4, 1.0);
  check((name + "_noise").c_str(), cal.noise.front(), 0.0, 0.1);
}

using Setter = std::function<void(ModelerConfig&, const YAML::Node&)>;

template <typename T>
Setter setter(T ModelerConfig::*field) {
  return [field](ModelerConfig& c, const YAML::Node& n) { c.*field = n.as<T>(); };
}

const std::map<std::string, Setter>& setters() {
  using C = ModelerConfig;
  static const std::map<std::string, Setter> table = {
      {"voxel_size", setter(&C::voxel_size)},
      {"max_modeled_points", setter(&C::max_modeled_points)},
      {"cluster_points", setter(&C::cluster_points)},
      {"split_error", setter(&C::split_error)},
      {"merge_distance", setter(&C::merge_distance)},
      {"min_cluster_points", setter(&C::min_cluster_points)},
      {"graph_neighbors", setter(&C::graph_neighbors)},
      {"n_low", setter(&C::n_low)},
      {"n_high", setter(&C::n_high)},
      {"psi_t", setter(&C::psi_t)},
      {"kmeans_iterations", setter(&C::kmeans_iterations)},
      {"slice_height", setter(&C::slice_height)},
      {"circle_threshold", setter(&C::circle_threshold)},
      {"ransac_iterations", setter(&C::ransac_iterations)},
      {"cylinder_threshold", setter(&C::cylinder_threshold)},
      {"disturbance_zero_run", setter(&C::disturbance_zero_run)},
      {"curvature_jump", setter(&C::curvature_jump)},
      {"min_segment_length", setter(&C::min_segment_length)},
      {"trunk_max_bend", setter(&C::trunk_max_bend)},
      {"trunk_max_segment_length", setter(&C::trunk_max_segment_length)},
      {"trunk_taper_profile", setter(&C::trunk_taper_profile)},
      {"branch_ray_split", setter(&C::branch_ray_split)},
      {"branch_keep_cut_off", setter(&C::branch_keep_cut_off)},
      {"branch_merge_curved", setter(&C::branch_merge_curved)},
      {"branch_ray_split_min_noise", setter(&C::branch_ray_split_min_noise)},
      {"branch_min_relative_points", setter(&C::branch_min_relative_points)},
      {"branch_cluster_tolerance", setter(&C::branch_cluster_tolerance)},
      {"branch_min_points", setter(&C::branch_min_points)},
      {"branch_fit_length", setter(&C::branch_fit_length)},
      {"ours_derive_parameters", setter(&C::ours_derive_parameters)},
      {"ours_remove_clutter", setter(&C::ours_remove_clutter)},
      {"ours_constrain_ransac", setter(&C::ours_constrain_ransac)},
      {"ours_follow_diameter", setter(&C::ours_follow_diameter)},
      {"ours_correct_noise_bias", setter(&C::ours_correct_noise_bias)},
      {"ours_branch_shell", setter(&C::ours_branch_shell)},
      {"noise_sigma", setter(&C::noise_sigma)},
      {"beam_spread", setter(&C::beam_spread)},
      {"trunk_max_tilt", setter(&C::trunk_max_tilt)},
      {"radius_continuity", setter(&C::radius_continuity)},
      {"branch_search_budget", setter(&C::branch_search_budget)},
      {"branch_max_radial_angle", setter(&C::branch_max_radial_angle)},
      {"branch_max_steep_angle", setter(&C::branch_max_steep_angle)},
      {"branch_max_azimuth", setter(&C::branch_max_azimuth)},
      {"branch_min_elevation", setter(&C::branch_min_elevation)},
      {"branch_max_diameter_ratio", setter(&C::branch_max_diameter_ratio)},
      {"branch_axis_gap", setter(&C::branch_axis_gap)},
      {"branch_inner_gap", setter(&C::branch_inner_gap)},
      {"branch_min_length", setter(&C::branch_min_length)},
      {"branch_min_height", setter(&C::branch_min_height)},
      {"floating_radius", setter(&C::floating_radius)},
      {"floating_min_neighbors", setter(&C::floating_min_neighbors)},
      {"wire_min_length", setter(&C::wire_min_length)},
      {"prune_ratio", setter(&C::prune_ratio)},
      {"seed", setter(&C::seed)},
      {"branch_raw_radius", setter(&C::branch_raw_radius)},
  };
  return table;
}

}  // namespace

ModelerConfig ModelerConfig::paper() {
  ModelerConfig c;
  c.ours_derive_parameters = false;
  c.ours_remove_clutter = false;
  c.ours_constrain_ransac = false;
  c.ours_follow_diameter = false;
  c.ours_correct_noise_bias = false;
  c.ours_branch_shell = false;
  c.trunk_max_bend = 0.0;
  c.trunk_max_segment_length = 0.0;
  c.trunk_taper_profile = false;
  c.branch_ray_split = false;
  c.branch_keep_cut_off = false;
  c.branch_merge_curved = false;
  c.branch_min_relative_points = 0.0;
  return c;
}

void ModelerConfig::validate() const {
  check("voxel_size", voxel_size, 0.0, 0.05);
  check("max_modeled_points", max_modeled_points, 10000, 50000000);
  check("cluster_points", cluster_points, 50, 1000000);
  check("split_error", split_error, 1e-4, 0.1);
  check("merge_distance", merge_distance, 0.0, 1.0);
  check("min_cluster_points", min_cluster_points, 6, 100000);
  check("graph_neighbors", graph_neighbors, 4, 1000);
  check("n_low", n_low, 0.0, 1.0);
  check("n_high", n_high, n_low, 1.0);
  check("psi_t", psi_t, 1.0, 90.0);
  check("kmeans_iterations", kmeans_iterations, 1, 1000);
  check("slice_height", slice_height, 0.01, 0.5);
  check("circle_threshold", circle_threshold, 1e-4, 0.1);
  check("ransac_iterations", ransac_iterations, 10, 100000);
  check("cylinder_threshold", cylinder_threshold, 1e-4, 0.1);
  check("disturbance_zero_run", disturbance_zero_run, 1, 100);
  check("curvature_jump", curvature_jump, 0.01, 1.0);
  check("min_segment_length", min_segment_length, 0.02, 5.0);
  check("trunk_max_bend", trunk_max_bend, 0.0, 1.0);
  if (trunk_max_segment_length != 0.0)
    check("trunk_max_segment_length", trunk_max_segment_length, 2.0 * min_segment_length, 10.0);
  check("branch_cluster_tolerance", branch_cluster_tolerance, 0.002, 0.5);
  check("branch_min_points", branch_min_points, 6, 1000000);
  check("branch_fit_length", branch_fit_length, 0.05, 2.0);
  check("noise_sigma", noise_sigma, -1.0, 0.1);
  check("beam_spread", beam_spread, 0.0, 0.1);

  check("trunk_max_tilt", trunk_max_tilt, 1.0, 90.0);
  check("radius_continuity", radius_continuity, 0.01, 10.0);
  check("branch_search_budget", branch_search_budget, 0, 1000000);
  check("branch_ray_split_min_noise", branch_ray_split_min_noise, 0.0, 1.0);
  check("branch_min_relative_points", branch_min_relative_points, 0.0, 1.0);
  check("branch_max_radial_angle", branch_max_radial_angle, 1.0, 90.0);
  check("branch_max_steep_angle", branch_max_steep_angle, branch_max_radial_angle, 90.0);
  check("branch_max_azimuth", branch_max_azimuth, 1.0, 180.0);
  check("branch_min_elevation", branch_min_elevation, -90.0, 90.0);
  check("branch_max_diameter_ratio", branch_max_diameter_ratio, 0.1, 10.0);
  check("branch_axis_gap", branch_axis_gap, 0.0, 1.0);
  check("branch_inner_gap", branch_inner_gap, 0.0, 1.0);
  check("branch_min_length", branch_min_length, 0.0, 2.0);
  check("branch_min_height", branch_min_height, 0.0, 5.0);

  check("floating_radius", floating_radius, 0.001, 0.5);
  check("floating_min_neighbors", floating_min_neighbors, 1, 1000);
  check("wire_min_length", wire_min_length, 0.1, 100.0);
  check("prune_ratio", prune_ratio, 0.0, 10.0);
  checkCalibration("trunk_calibration", trunk_calibration);
  checkCalibration("branch_calibration", branch_calibration);
}

ModelerConfig loadModelerConfig(const std::string& path) {
  ModelerConfig config;
  forEachYamlEntry(
      path, "tree_modeler", "tree modeler parameter",
      [&](const std::string& key, const YAML::Node& v) {
        if (key.rfind("trunk_calibration_", 0) == 0 || key.rfind("branch_calibration_", 0) == 0) {
          throw Error(ErrorCode::PARSE_ERROR,
                      path + ": '" + key +
                          "' is no longer a modeler parameter: radius tables are a "
                          "sensor calibration file now (calibrate_diameters; "
                          "tree_model --calibration, ~calibration_file)");
        }
        const auto it = setters().find(key);
        if (it == setters().end())
          return false;
        it->second(config, v);
        return true;
      });
  config.validate();
  return config;
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
