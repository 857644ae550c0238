#include "dormant_tree_modeling/emulation/ensemble_emulator.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <sstream>

#include "dormant_tree_modeling/aerotech/ascii_protocol.h"
#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace emulation {

using namespace aerotech;  // the emulator speaks the protocol the real client speaks

namespace {

constexpr double FAR_AWAY = 1e9;  // a free run's "target": it ends at a hard limit

std::string value(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%%%.6f", v);
  return buf;
}

std::vector<std::string> words(const std::string& line) {
  std::istringstream in(line);
  std::vector<std::string> w;
  std::string t;
  while (in >> t)
    w.push_back(t);
  return w;
}

bool parseDouble(const std::string& s, double& out) {
  char* end = nullptr;
  out = std::strtod(s.c_str(), &end);
  return !s.empty() && end == s.c_str() + s.size() && std::isfinite(out);
}

// Trapezoidal (or triangular) profile over distance d >= 0: time to cover it.
double profileDuration(double d, double v, double a) {
  const double ramp = v / a;  // time to reach v
  if (d >= v * ramp)
    return d / v + ramp;
  return 2.0 * std::sqrt(d / a);
}

// Distance covered after t on that profile.
double profileDistance(double d, double v, double a, double t) {
  const double total = profileDuration(d, v, a);
  if (t >= total)
    return d;
  const double peak = std::min(v, std::sqrt(d * a));
  const double ramp = peak / a;
  if (t < ramp)
    return 0.5 * a * t * t;
  const double cruise_end = total - ramp;
  if (t < cruise_end)
    return 0.5 * a * ramp * ramp + peak * (t - ramp);
  const double left = total - t;
  return d - 0.5 * a * left * left;
}

}  // namespace

std::vector<EmulatedAxisConfig> defaultStageAxes() {
  EmulatedAxisConfig rotary, slide;
  rotary.name = "X";
  rotary.max_velocity = 180.0;
  rotary.acceleration = 720.0;
  rotary.home_velocity = 90.0;
  rotary.min_limit = -360.0;
  rotary.max_limit = 360.0;
  slide.name = "Y";
  slide.max_velocity = 200.0;
  slide.acceleration = 1000.0;
  slide.home_velocity = 200.0;
  slide.min_limit = -5.0;  // a little travel beyond the soft limits (0 ... 600 mm)
  slide.max_limit = 605.0;
  return {rotary, slide};
}

EmulatedEnsemble::EmulatedEnsemble(std::vector<EmulatedAxisConfig> axes, EnsembleFaults faults)
    : faults_(std::move(faults)) {
  for (const auto& c : axes) {
    if (c.name.empty() || axes_.count(c.name) || !(c.min_limit < c.max_limit) ||
        c.max_velocity <= 0 || c.acceleration <= 0 || c.home_velocity <= 0) {
      throw Error(ErrorCode::INVALID_ARGUMENT, "emulated axis '" + c.name +
                                                   "': names must be unique, limits ordered, "
                                                   "velocities and acceleration positive");
    }
    Axis a;
    a.config = c;
    a.p0 = a.p1 = std::clamp(c.initial_position, c.min_limit, c.max_limit);
    axes_[c.name] = a;
    order_.push_back(c.name);
  }
}

EmulatedEnsemble::Axis* EmulatedEnsemble::find(const std::string& name) {
  return const_cast<Axis*>(static_cast<const EmulatedEnsemble*>(this)->find(name));
}

const EmulatedEnsemble::Axis* EmulatedEnsemble::find(const std::string& name) const {
  if (!name.empty() && name[0] == '@') {
    const int i = std::atoi(name.c_str() + 1);
    if (i < 0 || i >= static_cast<int>(order_.size()))
      return nullptr;
    return &axes_.at(order_[i]);
  }
  const auto it = axes_.find(name);
  return it == axes_.end() ? nullptr : &it->second;
}

double EmulatedEnsemble::moveEnd(const Axis& a) const {
  return a.t0 + profileDuration(std::abs(a.p1 - a.p0), a.v, a.a);
}

double EmulatedEnsemble::positionAt(const Axis& a, double t) const {
  if (a.fault_at >= 0 && t > a.fault_at)
    t = a.fault_at;
  const double d = std::abs(a.p1 - a.p0);
  if (d == 0 || t <= a.t0)
    return a.p0;
  const double s = profileDistance(d, a.v, a.a, t - a.t0);
  return a.p0 + (a.p1 > a.p0 ? s : -s);
}

double EmulatedEnsemble::velocityAt(const Axis& a, double t) const {
  constexpr double DT = 1e-3;
  return (positionAt(a, t) - positionAt(a, t - DT)) / DT;
}

// Bring an axis's state up to now: a move that ended, a fault that struck, a limit reached.
void EmulatedEnsemble::settle(Axis& a, double now_s) {
  if (a.fault_at >= 0 && now_s >= a.fault_at) {
    const double p = positionAt(a, a.fault_at);
    a.p0 = a.p1 = p;
    a.t0 = a.fault_at;
    a.fault |= a.fault_pending;
    a.fault_at = -1.0;
    a.fault_pending = 0;
    a.enabled = false;  // the controller disables a faulted axis
    a.homing = a.freerun = false;
    return;
  }
  if ((a.p0 != a.p1 || a.homing || a.freerun) && now_s >= moveEnd(a)) {
    a.p0 = a.p1;
    a.t0 = moveEnd(a);
    if (a.homing) {
      a.homing = false;
      a.homed = true;
    }
    a.freerun = false;
  }
}

void EmulatedEnsemble::stop(Axis& a, double now_s) {
  a.p0 = a.p1 = positionAt(a, now_s);
  a.t0 = now_s;
  a.fault_at = -1.0;
  a.fault_pending = 0;
  a.homing = a.freerun = false;
}

void EmulatedEnsemble::startMove(Axis& a, double target, double velocity, double now_s) {
  const double from = positionAt(a, now_s);
  const double to = std::clamp(target, a.config.min_limit, a.config.max_limit);
  a.t0 = now_s;
  a.p0 = from;
  a.p1 = to;
  a.v = std::min(std::abs(velocity), a.config.max_velocity);
  a.a = a.config.acceleration;
  a.fault_at = -1.0;
  a.fault_pending = 0;
  a.homing = a.freerun = false;
  if (to != target) {
    // The move runs into a hard limit: the axis faults when it gets there.
    a.fault_at = moveEnd(a);
    a.fault_pending = target > to ? FAULT_POSITIVE_HARD_LIMIT : FAULT_NEGATIVE_HARD_LIMIT;
  }
  ++moves_;
  if (!faults_.fault_axis.empty() && a.config.name == faults_.fault_axis &&
      moves_ == faults_.fault_on_move) {
    a.fault_at = 0.5 * (a.t0 + moveEnd(a));
    a.fault_pending = faults_.fault_bits;
  }
}

// The reply to a motion command: at once with WAIT MODE NOWAIT, else when the move ends.
EnsembleResponse EmulatedEnsemble::motion(Axis& a, double now_s) {
  if (wait_mode_nowait_)
    return {"%", now_s};
  const double end = a.fault_at >= 0 ? a.fault_at : moveEnd(a);
  return {a.fault_at >= 0 ? "#" : "%", std::max(now_s, end)};
}

// Long by design: one branch per controller command the client uses (docs/protocols.md), each
// a few lines, in one place as in the controller's command reference.
EnsembleResponse EmulatedEnsemble::handle(const std::string& line, double now_s) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (auto& [name, axis] : axes_)
    settle(axis, now_s);
  const EnsembleResponse invalid{"!", now_s};
  const EnsembleResponse fault{"#", now_s};
  const EnsembleResponse ok{"%", now_s};
  std::string text = line;
  // Queries: NAME(axis), PLANESTATUS(plane)
  const auto open = text.find('(');
  if (open != std::string::npos && text.back() == ')') {
    const std::string name = text.substr(0, open);
    if (faults_.invalid_commands.count(name))
      return invalid;
    const std::string argument = text.substr(open + 1, text.size() - open - 2);
    if (name == "PLANESTATUS")
      return argument == "0" ? EnsembleResponse{"%" + std::to_string(planeStatus(now_s)), now_s}
                             : invalid;
    const Axis* a = find(argument);
    if (!a)
      return invalid;
    if (name == "PFBKPROG")
      return {value(positionAt(*a, now_s)), now_s};
    if (name == "VFBK")
      return {value(velocityAt(*a, now_s)), now_s};
    if (name == "AXISFAULT")
      return {"%" + std::to_string(a->fault), now_s};
    if (name == "AXISSTATUS") {
      std::uint32_t bits = 0;
      const bool moving =
          a->p0 != a->p1 && now_s < moveEnd(*a) && now_s >= a->t0 + faults_.axis_status_latency_s;
      if (a->enabled)
        bits |= STATUS_ENABLED;
      if (a->homed)
        bits |= STATUS_HOMED;
      if (!moving)
        bits |= STATUS_IN_POSITION;
      if (moving)
        bits |= STATUS_MOVE_ACTIVE;
      if (a->homing)
        bits |= STATUS_HOMING;
      const double p = positionAt(*a, now_s);
      if (p >= a->config.max_limit)
        bits |= STATUS_POSITIVE_LIMIT;
      if (p <= a->config.min_limit)
        bits |= STATUS_NEGATIVE_LIMIT;
      return {"%" + std::to_string(bits), now_s};
    }
    return invalid;
  }
  const std::vector<std::string> w = words(text);
  if (w.empty())
    return invalid;
  if (faults_.invalid_commands.count(w[0]))
    return invalid;
  if (w[0] == "WAIT" && w.size() == 3 && w[1] == "MODE") {
    if (w[2] != "NOWAIT" && w[2] != "MOVEDONE")
      return invalid;
    wait_mode_nowait_ = w[2] == "NOWAIT";
    return ok;
  }
  if (w[0] == "ACKNOWLEDGEALL" && w.size() == 1) {
    for (auto& [name, axis] : axes_)
      axis.fault = 0;
    return ok;
  }
  if (w.size() < 2)
    return invalid;
  Axis* a = find(w[1]);
  if (!a)
    return invalid;
  if (w[0] == "ENABLE" && w.size() == 2) {
    if (a->fault)
      return fault;  // acknowledge the fault first
    a->enabled = true;
    return ok;
  }
  if (w[0] == "DISABLE" && w.size() == 2) {
    stop(*a, now_s);
    a->enabled = false;
    a->homing = a->freerun = false;
    return ok;
  }
  if (w[0] == "FAULTACK" && w.size() == 2) {
    a->fault = 0;
    return ok;
  }
  if (w[0] == "ABORT" && w.size() == 2) {
    // Decelerate to a stop from the current velocity.
    const double v = velocityAt(*a, now_s);
    const double stop = positionAt(*a, now_s) + v * std::abs(v) / (2.0 * a->config.acceleration);
    a->t0 = now_s;
    a->p0 = positionAt(*a, now_s);
    a->p1 = std::clamp(stop, a->config.min_limit, a->config.max_limit);
    a->v = std::max(std::abs(v), 1e-9);
    a->fault_at = -1.0;
    a->homing = a->freerun = false;
    return ok;
  }
  if (!a->enabled)
    return fault;  // motion on a disabled (or faulted) axis
  if (w[0] == "HOME" && w.size() == 2) {
    startMove(*a, 0.0, a->config.home_velocity, now_s);
    a->homing = true;
    a->homed = false;
    const double end = a->fault_at >= 0 ? a->fault_at : moveEnd(*a);
    return {a->fault_at >= 0 ? "#" : "%", end};  // HOME blocks until homed
  }
  if ((w[0] == "MOVEABS" || w[0] == "MOVEINC") && (w.size() == 3 || w.size() == 4)) {
    double target = 0, velocity = a->config.max_velocity;
    if (!parseDouble(w[2], target))
      return invalid;
    // The speed word: the axis as addressed, "F", the value ("XF5", "@1F5").
    const std::string speed_prefix = w[1] + "F";
    if (w.size() == 4 &&
        (w[3].compare(0, speed_prefix.size(), speed_prefix) != 0 ||
         !parseDouble(w[3].substr(speed_prefix.size()), velocity) || velocity <= 0))
      return invalid;
    if (w[0] == "MOVEINC")
      target += positionAt(*a, now_s);
    startMove(*a, target, velocity, now_s);
    return motion(*a, now_s);
  }
  if (w[0] == "FREERUN" && w.size() == 3) {
    double velocity = 0;
    if (!parseDouble(w[2], velocity))
      return invalid;
    if (velocity == 0) {
      stop(*a, now_s);
      return ok;
    }
    startMove(*a, velocity > 0 ? FAR_AWAY : -FAR_AWAY, velocity, now_s);
    a->freerun = true;
    return ok;
  }
  return invalid;
}

std::uint32_t EmulatedEnsemble::planeStatus(double now_s) const {
  for (const auto& [name, a] : axes_) {
    if (a.p0 != a.p1 && now_s < moveEnd(a))
      return PLANE_MOTION_ACTIVE;
  }
  return 0;
}

double EmulatedEnsemble::position(const std::string& axis, double now_s) const {
  std::lock_guard<std::mutex> lock(mutex_);
  const Axis* a = find(axis);
  if (!a)
    throw Error(ErrorCode::INVALID_ARGUMENT, "no emulated axis '" + axis + "'");
  return positionAt(*a, now_s);
}

}  // namespace emulation
}  // namespace dormant_tree_modeling
