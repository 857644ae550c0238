#include "dormant_tree_modeling/registration/node_config.h"

#include "dormant_tree_modeling/common/config_table.h"
#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace registration {

namespace {

ConfigTable<RegistrationNodeConfig> makeTable() {
  using N = RegistrationNodeConfig;
  ConfigTable<N> t("registration node parameter", "");
  t.add("config_file", &N::config_file,
        "Registration settings (config/registration.yaml); empty: the defaults.")
      .add("calibration_file", &N::calibration_file,
           "Sensor calibration holding the silhouette growth; empty: an ideal beam (warned).")
      .add("orchard_frame", &N::orchard_frame, "The frame the view hints are in.")
      .add("tree_frame", &N::tree_frame, "The frame the registered cloud is published in.")
      .add("laser_frame", &N::laser_frame, "The laser's frame (each view's sensor position).")
      .add("output_dir", &N::output_dir,
           "Registered cloud and report; empty: $ROS_HOME/registration.")
      .add("expected_views", &N::expected_views, 0, 100000,
           "Register once this many views arrived; 0: at the plan's end or on ~register.")
      .add("hint_timeout_s", &N::hint_timeout_s, 0.0, 60.0,
           "Wait for a view's platform transform (its hint).")
      .formerly("hint_timeout")
      .add("finished_wait_s", &N::finished_wait_s, 0.0, 600.0,
           "After the plan's end, for the last views to arrive.")
      .formerly("finished_wait")
      .add("end_of_input_timeout_s", &N::end_of_input_timeout_s, 0.0, 3600.0,
           "Register when input_watch_topic has been silent this long (replay); 0: off.")
      .formerly("end_of_input_timeout")
      .add("input_watch_topic", &N::input_watch_topic, "Topic whose silence ends the input.")
      .add("plan_progress_topic", &N::plan_progress_topic,
           "The acquisition's progress: its FINISHED state triggers the registration.");
  return t;
}

}  // namespace

const ConfigTable<RegistrationNodeConfig>& registrationNodeConfigTable() {
  static const ConfigTable<RegistrationNodeConfig> table = makeTable();
  return table;
}

void RegistrationNodeConfig::validate() const {
  registrationNodeConfigTable().check(*this);
  if (tree_frame.empty() || orchard_frame.empty() || tree_frame == orchard_frame)
    throw Error(ErrorCode::INVALID_ARGUMENT,
                "registration node parameters tree_frame and orchard_frame must be two "
                "different, non-empty frame names");
}

}  // namespace registration
}  // namespace dormant_tree_modeling
