#include "dormant_tree_modeling/aerotech/stage_controller.h"

#include <chrono>
#include <cmath>
#include <sstream>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace aerotech {

StageController::StageController(StageConfig config)
    : config_((config.validate(), std::move(config))),
      command_(config_.controller),
      feedback_(config_.controller) {}

const StageAxisConfig* StageController::axis(const std::string& name) const {
  for (const StageAxisConfig* a : {&config_.rotary, &config_.slide}) {
    if (name == a->axis || name == a->joint)
      return a;
  }
  return nullptr;
}

std::uint64_t StageController::reconnects() const {
  return command_.reconnects() + feedback_.reconnects();
}

void StageController::setUp() {
  command_.acknowledgeAll();
  for (const StageAxisConfig* a : {&config_.rotary, &config_.slide})
    command_.enable(a->axis);
  if (config_.home_on_start) {
    const MoveResult r = home();
    if (!r.success())
      throw Error(ErrorCode::IO_FAILURE, r.message);
  }
}

MoveResult StageController::home() {
  MoveResult r;
  try {
    // Also the way back from a fault: the controller disables a faulted axis.
    command_.acknowledgeAll();
    for (const StageAxisConfig* a : {&config_.rotary, &config_.slide}) {
      command_.enable(a->axis);
      command_.home(a->axis);
    }
    r.status = MoveStatus::OK;
    r.message = "homed";
    r.position = 0.0;
  } catch (const Error& e) {
    r.message = std::string("homing failed: ") + e.what();
  }
  return r;
}

MoveResult StageController::move(const MoveRequest& q) {
  MoveResult r;
  const StageAxisConfig* a = axis(q.axis);
  if (!a) {
    r.message = "unknown axis '" + q.axis + "' (have " + config_.rotary.axis + "/" +
                config_.rotary.joint + " and " + config_.slide.axis + "/" + config_.slide.joint +
                ")";
    return r;
  }
  if (!std::isfinite(q.target) || !std::isfinite(q.velocity) || q.velocity < 0) {
    r.message = "target must be finite and velocity finite and >= 0";
    r.status = MoveStatus::REFUSED;
    return r;
  }
  try {
    const double now = command_.position(a->axis) / a->scale;
    const double target = q.relative ? now + q.target : q.target;
    if (target < a->min_position || target > a->max_position) {
      std::ostringstream m;
      m << "target " << target << " is outside the soft limits [" << a->min_position << ", "
        << a->max_position << "] of axis " << a->axis;
      r.message = m.str();
      r.position = now;
      r.status = MoveStatus::REFUSED;
      return r;
    }
    const double velocity = q.velocity > 0 ? q.velocity : a->default_velocity;
    command_.moveAbsolute(a->axis, target * a->scale, velocity * a->scale);
    if (q.wait) {
      const double timeout = std::abs(target - now) / velocity + config_.move_timeout_margin_s;
      command_.waitForMove(a->axis, timeout);
    }
    r.position = command_.position(a->axis) / a->scale;
    r.status = MoveStatus::OK;
    r.message = q.wait ? "in position" : "moving";
  } catch (const Error& e) {
    r.message = e.what();
  }
  return r;
}

StageFeedback StageController::feedback() {
  StageFeedback f;
  f.rotary = feedback_.position(config_.rotary.axis) / config_.rotary.scale;
  f.slide = feedback_.position(config_.slide.axis) / config_.slide.scale;
  return f;
}

StageHealth StageController::health() {
  StageHealth h;
  h.rotary_status = feedback_.status(config_.rotary.axis);
  h.slide_status = feedback_.status(config_.slide.axis);
  h.rotary_faults = feedback_.faults(config_.rotary.axis);
  h.slide_faults = feedback_.faults(config_.slide.axis);
  return h;
}

void StageController::interrupt() {
  command_.interrupt();
  feedback_.interrupt();
}

void StageController::stopAll(double deadline_s) {
  command_.resume();
  const auto start = std::chrono::steady_clock::now();
  for (const StageAxisConfig* a : {&config_.rotary, &config_.slide}) {
    const double left =
        deadline_s -
        std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
    if (left <= 0)
      break;
    try {
      command_.abort(a->axis, left / 2);  // both axes within the deadline
    } catch (const Error&) {
    }
  }
}

}  // namespace aerotech
}  // namespace dormant_tree_modeling
