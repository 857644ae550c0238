#pragma once

#include <string>

namespace dormant_tree_modeling {

template <typename Config>
class ConfigTable;

namespace registration {

/// @brief The registration node's parameters (launch/registration.launch); the registration's
/// own settings come from config_file.
struct RegistrationNodeConfig {
  std::string config_file;  ///< registration settings (config/registration.yaml); empty: defaults
  std::string calibration_file;  ///< sensor calibration with the silhouette growth; empty: none
  std::string orchard_frame = "orchard";
  std::string tree_frame = "tree";
  std::string laser_frame = "laser";
  std::string output_dir;  ///< empty: $ROS_HOME/registration
  int expected_views = 0;  ///< register once this many views arrived; 0: on the plan's end
  double hint_timeout_s = 0.5;
  double finished_wait_s = 10.0;
  double end_of_input_timeout_s = 0.0;  ///< 0: off
  std::string input_watch_topic;
  std::string plan_progress_topic;
  /// @throws Error INVALID_ARGUMENT naming the field
  void validate() const;
};

/// @brief The keys of the registration node: its parameters, docs/configuration.md.
const ConfigTable<RegistrationNodeConfig>& registrationNodeConfigTable();

}  // namespace registration
}  // namespace dormant_tree_modeling
