#include "dormant_tree_modeling/aerotech/stage_config.h"

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace aerotech {

void StageAxisConfig::validate(const std::string& which) const {
  auto require = [&](bool ok, const std::string& m) {
    if (!ok)
      throw Error(ErrorCode::INVALID_ARGUMENT, "stage " + which + " axis: " + m);
  };
  require(!axis.empty() && axis.find_first_of(" \n()") == std::string::npos,
          "axis must be a controller axis name without spaces, is '" + axis + "'");
  require(!joint.empty(), "joint name must not be empty");
  require(scale > 0, "scale must be > 0");
  require(default_velocity > 0, "default_velocity must be > 0");
  require(min_position < max_position, "min_position must be below max_position");
}

void StageConfig::validate() const {
  controller.validate();
  rotary.validate("rotary");
  slide.validate("slide");
  if (rotary.axis == slide.axis || rotary.joint == slide.joint)
    throw Error(ErrorCode::INVALID_ARGUMENT, "the rotary and slide axes must differ");
  if (!(joint_state_rate >= 1.0 && joint_state_rate <= 1000.0))
    throw Error(ErrorCode::INVALID_ARGUMENT, "joint_state_rate must be in 1..1000 Hz");
  if (move_timeout_margin_s <= 0)
    throw Error(ErrorCode::INVALID_ARGUMENT, "move_timeout_margin must be > 0 s");
}

}  // namespace aerotech
}  // namespace dormant_tree_modeling
