#pragma once

#include <atomic>
#include <memory>
#include <string>
#include <thread>

#include "dormant_tree_modeling/emulation/lms111_emulator.h"

namespace dormant_tree_modeling {
namespace emulation {

/// @brief Where the emulator listens. A port of 0 picks a free one (see the accessors), -1
/// disables that protocol.
struct LmsServerConfig {
  std::string address = "127.0.0.1";
  int cola_a_port = 2111;
  int cola_b_port = 2112;
};

/// @brief Serves an EmulatedLms111 over TCP as the device does: CoLa-A and CoLa-B on their
/// ports, any number of clients, scans streamed at the configured frequency to every client
/// that switched the stream on, and the faults of LmsFaults. Runs its own I/O thread.
class LmsServer {
 public:
  /// @throws Error IO_FAILURE when a port cannot be bound
  LmsServer(std::shared_ptr<EmulatedLms111> device, LmsServerConfig options = {});
  ~LmsServer();
  LmsServer(const LmsServer&) = delete;
  LmsServer& operator=(const LmsServer&) = delete;

  /// @brief Bound CoLa-A / CoLa-B port (-1 when disabled).
  int colaAPort() const;
  int colaBPort() const;
  /// @brief Scan telegrams sent since start (every client counted once per telegram).
  std::size_t telegramsSent() const;
  /// @brief Connections accepted since start.
  std::size_t connectionsAccepted() const;
  /// @brief Stop serving and join the I/O thread (also done by the destructor).
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::thread thread_;
};

}  // namespace emulation
}  // namespace dormant_tree_modeling
