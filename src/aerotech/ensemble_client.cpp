#include "dormant_tree_modeling/aerotech/ensemble_client.h"

#include <algorithm>
#include <chrono>
#include <thread>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace aerotech {

namespace {

// The plane the ASCII interface's motion commands run in.
constexpr int MOTION_PLANE = 0;
// Longest wait between two looks at the interrupt flag, s.
constexpr double INTERRUPT_POLL_S = 0.05;

double steadySeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

void EnsembleClientConfig::validate() const {
  auto require = [](bool ok, const std::string& m) {
    if (!ok)
      throw Error(ErrorCode::INVALID_ARGUMENT, "aerotech client: " + m);
  };
  require(!host.empty(), "host must not be empty");
  require(port > 0 && port < 65536, "port must be in 1..65535");
  require(connect_timeout_s > 0 && reply_timeout_s > 0 && home_timeout_s > 0,
          "timeouts must be > 0");
}

EnsembleClient::EnsembleClient(EnsembleClientConfig config) : config_(std::move(config)) {
  config_.validate();
}

bool EnsembleClient::connected() const {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  return connection_.isOpen();
}

// Lock-free: diagnostics ask while another thread waits on a silent controller.
std::uint64_t EnsembleClient::reconnects() const {
  const std::uint64_t n = connects_;
  return n > 0 ? n - 1 : 0;
}

void EnsembleClient::close() {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  connection_.close();
}

void EnsembleClient::interrupt() {
  interrupted_ = true;
}

void EnsembleClient::resume() {
  interrupted_ = false;
}

void EnsembleClient::throwIfInterrupted(const std::string& line) {
  if (!interrupted_)
    return;
  connection_.close();  // a reply still on its way would be out of step
  throw Error(ErrorCode::IO_FAILURE, "'" + line + "' interrupted: the client is stopping");
}

void EnsembleClient::ensureConnected(double timeout_s) {
  if (connection_.isOpen())
    return;
  throwIfInterrupted("connect");
  framer_.clear();
  connection_.connect(config_.host, config_.port, std::min(timeout_s, config_.connect_timeout_s));
  ++connects_;
  const Reply r = exchange(command::waitModeNoWait(), std::min(timeout_s, config_.reply_timeout_s));
  if (!r.ok()) {
    connection_.close();
    throw Error(ErrorCode::IO_FAILURE, std::string("the controller refused WAIT MODE NOWAIT: ") +
                                           replyStatusName(r.status));
  }
}

Reply EnsembleClient::exchange(const std::string& line, double timeout_s) {
  connection_.send(line + "\n", timeout_s);
  const double deadline = steadySeconds() + timeout_s;
  for (;;) {
    if (auto reply = framer_.next()) {
      try {
        return parseReply(*reply);
      } catch (const Error& e) {
        connection_.close();  // out of step with the controller: start afresh
        throw Error(ErrorCode::IO_FAILURE, "reply to '" + line + "': " + e.what());
      }
    }
    throwIfInterrupted(line);
    const double left = deadline - steadySeconds();
    if (left <= 0) {
      // A late reply would be taken for the next command's: drop the connection instead.
      connection_.close();
      throw Error(ErrorCode::IO_FAILURE,
                  "no reply to '" + line + "' within " + std::to_string(timeout_s) + " s");
    }
    const std::string bytes = connection_.receiveSome(std::min(left, INTERRUPT_POLL_S));
    framer_.feed(bytes);
  }
}

Reply EnsembleClient::send(const std::string& line, double timeout_s, bool idempotent) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  try {
    ensureConnected(timeout_s);
    return exchange(line, timeout_s);
  } catch (const Error& e) {
    connection_.close();
    if (!idempotent || interrupted_)
      throw;
  }
  ensureConnected(timeout_s);
  return exchange(line, timeout_s);
}

Reply EnsembleClient::checked(const std::string& line, const std::string& axis, double timeout_s,
                              bool idempotent) {
  std::lock_guard<std::recursive_mutex> lock(mutex_);
  const Reply r = send(line, timeout_s, idempotent);
  if (r.ok())
    return r;
  std::string why = replyStatusName(r.status);
  if (r.status == ReplyStatus::FAULT && !axis.empty()) {
    try {
      const Reply f = send(command::axisFault(axis), config_.reply_timeout_s, true);
      if (f.ok())
        why += " (" + describeFaults(static_cast<std::uint32_t>(f.number())) + ")";
    } catch (const Error&) {
    }
  }
  throw Error(ErrorCode::IO_FAILURE, "'" + line + "' failed: " + why);
}

void EnsembleClient::enable(const std::string& axis) {
  checked(command::enable(axis), axis, config_.reply_timeout_s, true);
}
void EnsembleClient::disable(const std::string& axis) {
  checked(command::disable(axis), axis, config_.reply_timeout_s, true);
}
void EnsembleClient::home(const std::string& axis) {
  checked(command::home(axis), axis, config_.home_timeout_s, false);
}
void EnsembleClient::moveAbsolute(const std::string& axis, double position, double velocity) {
  checked(command::moveAbsolute(axis, position, velocity), axis, config_.reply_timeout_s, false);
}
void EnsembleClient::moveIncremental(const std::string& axis, double distance, double velocity) {
  checked(command::moveIncremental(axis, distance, velocity), axis, config_.reply_timeout_s, false);
}
void EnsembleClient::freerun(const std::string& axis, double velocity) {
  checked(command::freerun(axis, velocity), axis, config_.reply_timeout_s, false);
}
void EnsembleClient::abort(const std::string& axis, double timeout_s) {
  checked(command::abort(axis), axis, timeout_s > 0 ? timeout_s : config_.reply_timeout_s, true);
}
void EnsembleClient::faultAck(const std::string& axis) {
  checked(command::faultAck(axis), axis, config_.reply_timeout_s, true);
}
void EnsembleClient::acknowledgeAll() {
  checked(command::acknowledgeAll(), "", config_.reply_timeout_s, true);
}
double EnsembleClient::position(const std::string& axis) {
  return checked(command::positionFeedback(axis), axis, config_.reply_timeout_s, true).number();
}
double EnsembleClient::velocity(const std::string& axis) {
  return checked(command::velocityFeedback(axis), axis, config_.reply_timeout_s, true).number();
}
AxisStatus EnsembleClient::status(const std::string& axis) {
  const Reply r = checked(command::axisStatus(axis), axis, config_.reply_timeout_s, true);
  return AxisStatus{static_cast<std::uint32_t>(r.number())};
}
std::uint32_t EnsembleClient::faults(const std::string& axis) {
  return static_cast<std::uint32_t>(
      checked(command::axisFault(axis), axis, config_.reply_timeout_s, true).number());
}

bool EnsembleClient::planeMoving() {
  const Reply r = checked(command::planeStatus(MOTION_PLANE), "", config_.reply_timeout_s, true);
  return (static_cast<std::uint32_t>(r.number()) & PLANE_MOTION_ACTIVE) != 0;
}

void EnsembleClient::waitForMove(const std::string& axis, double timeout_s, double poll_s) {
  const double deadline = steadySeconds() + timeout_s;
  for (;;) {
    const AxisStatus s = status(axis);
    const std::uint32_t f = faults(axis);
    if (f != 0) {
      throw Error(ErrorCode::IO_FAILURE,
                  "axis " + axis + " faulted during the move: " + describeFaults(f));
    }
    // The plane's motion flag as well: AXISSTATUS alone can report "in position, no move"
    // before a just-issued move starts, or through a jog's end (motorAerotech's fix .13).
    if (s.inPosition() && !s.moveActive() && !planeMoving())
      return;
    if (!s.enabled())
      throw Error(ErrorCode::IO_FAILURE, "axis " + axis + " was disabled during the move");
    throwIfInterrupted("waiting for axis " + axis);
    if (steadySeconds() > deadline) {
      throw Error(ErrorCode::IO_FAILURE, "axis " + axis + " not in position within " +
                                             std::to_string(timeout_s) + " s (" + s.describe() +
                                             ")");
    }
    std::this_thread::sleep_for(std::chrono::duration<double>(poll_s));
  }
}

}  // namespace aerotech
}  // namespace dormant_tree_modeling
