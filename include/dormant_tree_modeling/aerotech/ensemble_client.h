#pragma once

#include <atomic>
#include <cstdint>
#include <mutex>
#include <string>

#include "dormant_tree_modeling/aerotech/ascii_protocol.h"
#include "dormant_tree_modeling/common/tcp_connection.h"

namespace dormant_tree_modeling {
namespace aerotech {

/// @brief Where the controller is and how patient to be (s).
struct EnsembleClientConfig {
  std::string host = "192.168.1.16";
  int port = 8000;  ///< Ethernet socket 2
  double connect_timeout_s = 2.0;
  double reply_timeout_s = 2.0;  ///< queries and non-blocking commands
  double home_timeout_s = 60.0;  ///< HOME blocks until the axis is homed
  /// @throws Error INVALID_ARGUMENT naming the bad field
  void validate() const;
};

/// @brief Client of the Ensemble ASCII interface (Boost.Asio through TcpConnection). Puts the
/// controller in WAIT MODE NOWAIT on every (re)connection so that moves never block the
/// interpreter; reconnects on the next call when the controller dropped the socket (it closes
/// idle ones); retries an idempotent query once after a reconnect but never a motion command.
/// Replies `!`, `#`, `$` become Error exceptions with the decoded reason (for `#` the axis's
/// AXISFAULT bits by name). Thread-safe: one command at a time.
class EnsembleClient {
 public:
  /// @throws Error INVALID_ARGUMENT for a bad configuration
  explicit EnsembleClient(EnsembleClientConfig config);

  void enable(const std::string& axis);
  void disable(const std::string& axis);
  /// @brief Blocks until homed (home_timeout_s).
  void home(const std::string& axis);
  void moveAbsolute(const std::string& axis, double position, double velocity);
  void moveIncremental(const std::string& axis, double distance, double velocity);
  void freerun(const std::string& axis, double velocity);
  /// @param timeout_s reply timeout, connection included; <= 0: reply_timeout_s
  void abort(const std::string& axis, double timeout_s = -1.0);
  void faultAck(const std::string& axis);
  void acknowledgeAll();
  double position(const std::string& axis);
  double velocity(const std::string& axis);
  AxisStatus status(const std::string& axis);
  std::uint32_t faults(const std::string& axis);

  /// @brief Whether motion plane 0 (the one the ASCII interface's moves run in) is moving.
  bool planeMoving();

  /// @brief Poll until the axis is in position with no move active, in the axis or its plane.
  /// @throws Error IO_FAILURE on an axis fault (decoded) or when timeout_s passes
  void waitForMove(const std::string& axis, double timeout_s, double poll_s = 0.01);

  /// @brief Send one line and return its reply, reconnecting first when needed.
  /// @param idempotent retry once on a fresh connection if the transport fails
  /// @throws Error IO_FAILURE on transport failure or timeout
  Reply send(const std::string& line, double timeout_s, bool idempotent);

  /// @brief Make every blocking call return within INTERRUPT_POLL_S with an IO_FAILURE
  /// "interrupted", until resume(). Safe from any thread; for shutting down promptly.
  void interrupt();
  void resume();

  bool connected() const;
  std::uint64_t reconnects() const;
  const EnsembleClientConfig& config() const { return config_; }
  void close();

 private:
  Reply exchange(const std::string& line, double timeout_s);
  void ensureConnected(double timeout_s);
  void throwIfInterrupted(const std::string& line);
  /// Runs a command and throws the decoded reason on anything but success.
  Reply checked(const std::string& line, const std::string& axis, double timeout_s,
                bool idempotent);

  EnsembleClientConfig config_;
  TcpConnection connection_;
  LineFramer framer_;
  std::atomic<std::uint64_t> connects_{0};
  std::atomic<bool> interrupted_{false};
  mutable std::recursive_mutex mutex_;
};

}  // namespace aerotech
}  // namespace dormant_tree_modeling
