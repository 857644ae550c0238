#include "dormant_tree_modeling/acquisition/node_configs.h"

#include "dormant_tree_modeling/common/config_table.h"
#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace acquisition {

namespace {

void addSweep(ConfigTable<AssemblerConfig>& t) {
  using S = SweepConfig;
  t.group(&AssemblerConfig::sweep)
      .names("mode", &S::continuous, {{"continuous", true}, {"step", false}},
             "continuous: the stage turns under the streaming laser; step: the paper's "
             "step-and-scan.")
      .add("theta_min_deg", &S::theta_min_deg, -180.0, 180.0,
           "The sweep covers theta_min_deg <= theta < theta_max_deg (docs/hardware.md).")
      .formerly("theta_min")
      .add("theta_max_deg", &S::theta_max_deg, -180.0, 180.0, "End of the sweep.")
      .formerly("theta_max")
      .add("theta_step_deg", &S::theta_step_deg, 0.01, 90.0,
           "One scan line per step (0.45: 200 lines).")
      .formerly("theta_step")
      .add("sweep_margin_deg", &S::margin_deg, 0.0, 45.0,
           "Past each end, for the stage to reach speed (continuous).")
      .formerly("sweep_margin")
      .add("settle_time_s", &S::settle_s, 0.0, 10.0,
           "After a step before a line is taken (step mode).")
      .formerly("settle_time");
}

void addProcessing(ConfigTable<AssemblerConfig>& t) {
  using P = ViewProcessingConfig;
  t.group(&AssemblerConfig::processing)
      .add("floating_threshold_m", &P::floating_threshold_m, 0.001, 1.0, "rho_T of Eq. 1.")
      .formerly("floating_threshold")
      .add("smoothing_iterations", &P::smoothing_iterations, 0, 20,
           "Range smoothing passes (the modeler's calibration assumes none).")
      .add("isolate", &P::isolate, "Cut the target tree out of the view.");
  using I = IsolationConfig;
  ConfigTable<ViewProcessingConfig> nested(t.what(), "");
  nested.group(&ViewProcessingConfig::isolation)
      .add("crop_radius_m", &I::crop_radius_m, 0.05, 10.0, "Kept around the trunk axis.")
      .formerly("crop_radius")
      .add("hint_sigma_m", &I::hint_sigma_m, 0.01, 10.0,
           "How far the trunk may be from where the plan expects it.")
      .formerly("hint_sigma")
      .add("max_height_m", &I::max_height_m, 0.1, 50.0, "Kept up to this height above the ground.")
      .formerly("max_height");
  t.include("", &AssemblerConfig::processing, nested);
}

ConfigTable<AssemblerConfig> makeAssemblerTable() {
  using A = AssemblerConfig;
  ConfigTable<A> t("scan assembler parameter", "");
  addSweep(t);
  t.topLevel()
      .add("rotary_axis", &A::rotary_axis, "The rotary axis as the stage controller names it.")
      .add("rotary_joint", &A::rotary_joint, "Its joint in joint_states.")
      .add("move_axis_service", &A::move_axis_service, "The stage controller's service.")
      .add("platform_frame", &A::platform_frame, "The view clouds' frame.")
      .add("rotary_stage_frame", &A::rotary_stage_frame, "The rotary stage's tf frame.")
      .add("tree_frame", &A::tree_frame,
           "The plan's tree frame: its origin (tf) is where the trunk should be.")
      .add("tree_distance_m", &A::tree_distance_m, 0.01, 100.0,
           "Straight ahead, where the trunk is assumed without that transform.")
      .formerly("tree_distance")
      .add("max_missing_rows", &A::max_missing_rows, 0.0, 0.99,
           "Share of the plan's rows a view may lack before it fails.")
      .add("buffer_s", &A::buffer_s, 10.0, 3600.0, "Of scans and stage positions kept.")
      .formerly("buffer_seconds")
      .add("passive", &A::passive,
           "Assemble the sweeps seen on the topics (replaying a bag) instead of serving "
           "acquire_view.");
  addProcessing(t);
  return t;
}

ConfigTable<AcquisitionNodeConfig> makeAcquisitionTable() {
  using N = AcquisitionNodeConfig;
  ConfigTable<N> t("acquisition parameter", "");
  t.add("plan_file", &N::plan_file, "View plan YAML (view plan keys below); empty: the default.")
      .add("output_dir", &N::output_dir, "Where the bag and the views go.")
      .add("tree_name", &N::tree_name, "A plain file name: the bag and the views are named by it.")
      .add("move_axis_service", &N::move_axis_service, "The stage controller's service.")
      .add("acquire_view_service", &N::acquire_view_service, "The scan assembler's service.")
      .add("slide_axis", &N::slide_axis, "The slide as the stage controller names it.")
      .add("orchard_frame", &N::orchard_frame, "The plan's frame.")
      .add("platform_frame", &N::platform_frame, "The platform's frame.")
      .add("slide_centre_m", &N::slide_centre_m, -10.0, 10.0,
           "Slide position of the plan's centre.")
      .formerly("slide_centre")
      .add("slide_velocity_mps", &N::slide_velocity_mps, 0.0, 1.0,
           "Of the slide moves between views; 0: the stage's default.")
      .formerly("slide_velocity")
      .add("max_retries", &N::max_retries, 0, 10, "Per view.")
      .add("drain_s", &N::drain_s, 0.0, 60.0,
           "Recorded past the last view before the bag is closed.")
      .formerly("drain_seconds")
      .add("service_wait_s", &N::service_wait_s, 0.01, 600.0,
           "For the stage and assembler services at start.")
      .formerly("service_wait")
      .add("record_topics", &N::record_topics, "Topics recorded into the bag.")
      .add("autostart", &N::autostart, "Run the plan at once (else on ~start).");
  return t;
}

}  // namespace

const ConfigTable<AssemblerConfig>& assemblerConfigTable() {
  static const ConfigTable<AssemblerConfig> table = makeAssemblerTable();
  return table;
}

const ConfigTable<AcquisitionNodeConfig>& acquisitionNodeConfigTable() {
  static const ConfigTable<AcquisitionNodeConfig> table = makeAcquisitionTable();
  return table;
}

void AssemblerConfig::validate() const {
  assemblerConfigTable().check(*this);
  sweep.validate();
  processing.validate();
}

void AcquisitionNodeConfig::validate() const {
  const auto& table = acquisitionNodeConfigTable();
  table.check(*this);
  table.require(!tree_name.empty() && tree_name.find('/') == std::string::npos,
                "tree_name must be a plain file name");
  table.require(!record_topics.empty(), "record_topics must not be empty");
}

}  // namespace acquisition
}  // namespace dormant_tree_modeling
