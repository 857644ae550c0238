#include "dormant_tree_modeling/aerotech/stage_config.h"

#include "dormant_tree_modeling/common/config_table.h"
#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace aerotech {

namespace {

constexpr const char* WHAT = "stage controller parameter";

ConfigTable<StageAxisConfig> makeAxisTable() {
  using A = StageAxisConfig;
  ConfigTable<A> t(WHAT, "");
  t.add("axis", &A::axis, "Controller axis name (or @index).")
      .add("joint", &A::joint, "JointState and tf joint name.")
      .add("scale", &A::scale, 1e-6, 1e6,
           "Controller units per service unit (rotary: deg per deg; slide: mm per m).")
      .add("default_velocity", &A::default_velocity, 1e-6, 1e4,
           "Service units (rotary deg, slide m) per s, used when a request gives 0.")
      .add("min_position", &A::min_position, -1e6, 1e6, "Soft limit, service units.")
      .add("max_position", &A::max_position, -1e6, 1e6, "Soft limit, service units.");
  return t;
}

const ConfigTable<StageAxisConfig>& axisTable() {
  static const ConfigTable<StageAxisConfig> table = makeAxisTable();
  return table;
}

void addController(ConfigTable<StageNodeConfig>& t) {
  using C = EnsembleClientConfig;
  ConfigTable<StageConfig> stage(WHAT, "");
  stage.group(&StageConfig::controller)
      .add("host", &C::host, "Controller address.")
      .add("port", &C::port, 1, 65535, "Ethernet socket 2 (8000).")
      .add("connect_timeout_s", &C::connect_timeout_s, 0.01, 600.0, "TCP connect.")
      .formerly("connect_timeout")
      .add("reply_timeout_s", &C::reply_timeout_s, 0.01, 600.0,
           "Per command (queries and non-blocking commands).")
      .formerly("reply_timeout")
      .add("home_timeout_s", &C::home_timeout_s, 0.01, 3600.0, "HOME blocks until homed.")
      .formerly("home_timeout")
      .topLevel()
      .add("home_on_start", &StageConfig::home_on_start, "Home both axes once connected.")
      .add("joint_state_rate_hz", &StageConfig::joint_state_rate_hz, 1.0, 1000.0,
           "Position feedback -> joint_states and tf.")
      .formerly("joint_state_rate")
      .add("move_timeout_margin_s", &StageConfig::move_timeout_margin_s, 0.01, 600.0,
           "Beyond a move's nominal duration before it counts as failed.")
      .formerly("move_timeout_margin");
  using G = geometry::StageGeometry;
  stage.group(&StageConfig::geometry)
      .add("platform_to_slide_base_m", &G::platform_to_slide_base, -10.0, 10.0,
           "Mounting (architecture.md frames): the slide's centre in the platform frame.")
      .formerly("platform_to_slide_base")
      .add("carriage_to_stage_m", &G::carriage_to_stage, -10.0, 10.0,
           "The rotary stage on the slide carriage.")
      .formerly("carriage_to_stage")
      .add("stage_to_laser_m", &G::stage_to_laser, -10.0, 10.0,
           "The laser on the rotary stage (rotated by theta about z).")
      .formerly("stage_to_laser");
  t.include("", &StageNodeConfig::stage, stage);
}

/// The axes last: their keys are groups (rotary.*, slide.*), after every plain key.
void addAxes(ConfigTable<StageNodeConfig>& t) {
  ConfigTable<StageConfig> axes(WHAT, "");
  axes.include("rotary", &StageConfig::rotary, axisTable())
      .include("slide", &StageConfig::slide, axisTable());
  t.include("", &StageNodeConfig::stage, axes);
}

ConfigTable<StageNodeConfig> makeNodeTable() {
  using N = StageNodeConfig;
  ConfigTable<N> t(WHAT, "");
  addController(t);
  t.topLevel()
      .add("platform_frame", &N::platform_frame, "tf frame of the platform.")
      .add("slide_base_frame", &N::slide_base_frame, "tf frame of the slide's fixed part.")
      .add("slide_carriage_frame", &N::slide_carriage_frame, "tf frame of the carriage.")
      .add("rotary_stage_frame", &N::rotary_stage_frame, "tf frame of the rotary stage.")
      .add("laser_frame", &N::laser_frame, "tf frame of the laser.")
      .add("reconnect_min_s", &N::reconnect_min_s, 0.001, 600.0,
           "First back-off after a failed set-up or feedback round; doubles per failure.")
      .formerly("reconnect_min")
      .add("reconnect_max_s", &N::reconnect_max_s, 0.001, 3600.0, "Longest back-off.")
      .formerly("reconnect_max");
  addAxes(t);
  return t;
}

}  // namespace

const ConfigTable<StageNodeConfig>& stageNodeConfigTable() {
  static const ConfigTable<StageNodeConfig> table = makeNodeTable();
  return table;
}

void StageAxisConfig::validate(const std::string& which) const {
  axisTable().check(*this);
  axisTable().require(
      !axis.empty() && axis.find_first_of(" \n()") == std::string::npos,
      which + ".axis must be a controller axis name without spaces, is '" + axis + "'");
  axisTable().require(!joint.empty(), which + ".joint must not be empty");
  axisTable().require(min_position < max_position,
                      which + ".min_position must be below max_position");
}

void StageConfig::validate() const {
  controller.validate();
  rotary.validate("rotary");
  slide.validate("slide");
  stageNodeConfigTable().require(rotary.axis != slide.axis && rotary.joint != slide.joint,
                                 "rotary and slide must name different axes and joints");
  stageNodeConfigTable().require(joint_state_rate_hz >= 1.0 && joint_state_rate_hz <= 1000.0,
                                 "joint_state_rate_hz must be in [1, 1000]");
  stageNodeConfigTable().require(move_timeout_margin_s > 0, "move_timeout_margin_s must be > 0");
}

void StageNodeConfig::validate() const {
  stage.validate();
  stageNodeConfigTable().check(*this);
  stageNodeConfigTable().require(reconnect_max_s >= reconnect_min_s,
                                 "reconnect_max_s must be at least reconnect_min_s");
}

}  // namespace aerotech
}  // namespace dormant_tree_modeling
