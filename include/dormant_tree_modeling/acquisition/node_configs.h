#pragma once

#include <string>
#include <vector>

#include "dormant_tree_modeling/acquisition/sweep.h"
#include "dormant_tree_modeling/acquisition/view_processing.h"

namespace dormant_tree_modeling {

template <typename Config>
class ConfigTable;

namespace acquisition {

/// @brief The scan assembler node's parameters (config/scan_assembler.yaml): one rotary sweep
/// to one view.
struct AssemblerConfig {
  SweepConfig sweep;
  ViewProcessingConfig processing;
  std::string rotary_axis = "X";  ///< as the stage controller names it
  std::string rotary_joint = "rotary_stage_joint";
  std::string move_axis_service = "/stage/stage_controller/move_axis";
  std::string platform_frame = "platform";
  std::string rotary_stage_frame = "rotary_stage";
  /// The plan's tree frame: its origin (tf) is where the trunk should be.
  std::string tree_frame = "orchard";
  double tree_distance_m = 1.5;    ///< straight ahead, where the trunk is assumed without tf
  double max_missing_rows = 0.05;  ///< share of the plan's rows a view may lack
  double buffer_s = 60.0;          ///< of scans and stage positions kept
  bool passive = false;            ///< assemble the sweeps seen on the topics (replay), no service
  /// @throws Error INVALID_ARGUMENT naming the field
  void validate() const;
};

/// @brief The acquisition node's parameters (launch/acquisition.launch): the plan and where its
/// views go.
struct AcquisitionNodeConfig {
  std::string plan_file;  ///< view plan YAML (config/view_plan.yaml); empty: the default plan
  std::string output_dir = "scans";
  std::string tree_name = "tree";  ///< a plain file name: the bag and the views are named by it
  std::string move_axis_service = "/stage/stage_controller/move_axis";
  std::string acquire_view_service = "/assembler/scan_assembler/acquire_view";
  std::string slide_axis = "Y";
  std::string orchard_frame = "orchard";
  std::string platform_frame = "platform";
  double slide_centre_m = 0.3;      ///< slide position of the plan's centre
  double slide_velocity_mps = 0.0;  ///< of the moves between views; 0: the stage's default
  int max_retries = 2;              ///< per view
  double drain_s = 1.0;             ///< recorded past the last view before the bag is closed
  double service_wait_s = 30.0;     ///< for the stage and assembler services at start
  std::vector<std::string> record_topics = {
      "/lms111/scan", "/stage/joint_states",   "/tf",
      "/tf_static",   "/assembler/view_cloud", "/acquisition/progress"};
  bool autostart = false;  ///< run the plan at once (else on ~start)
  /// @throws Error INVALID_ARGUMENT naming the field
  void validate() const;
};

/// @brief The keys of the scan assembler node: YAML, its parameters, docs/configuration.md.
const ConfigTable<AssemblerConfig>& assemblerConfigTable();
/// @brief The keys of the acquisition node.
const ConfigTable<AcquisitionNodeConfig>& acquisitionNodeConfigTable();

}  // namespace acquisition
}  // namespace dormant_tree_modeling
