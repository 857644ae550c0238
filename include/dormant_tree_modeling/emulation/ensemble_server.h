#pragma once

#include <memory>
#include <string>
#include <thread>

#include "dormant_tree_modeling/emulation/ensemble_emulator.h"

namespace dormant_tree_modeling {
namespace emulation {

/// @brief Serves an EmulatedEnsemble on TCP as the controller's ASCII socket does: one line a
/// command, one reply line each, in order, blocking replies (HOME, WAIT MODE MOVEDONE) sent
/// when due; sockets dropped after EnsembleFaults::drop_after_commands or when idle longer than
/// idle_timeout_s. Runs its own I/O thread.
class EnsembleServer {
 public:
  /// @param port 0 picks a free port (see port())
  /// @throws Error IO_FAILURE when the port cannot be bound
  EnsembleServer(std::shared_ptr<EmulatedEnsemble> controller, const std::string& address,
                 int port);
  ~EnsembleServer();
  EnsembleServer(const EnsembleServer&) = delete;
  EnsembleServer& operator=(const EnsembleServer&) = delete;

  int port() const;
  /// @brief Seconds on the clock the controller is driven with (for its position()).
  double now() const;
  std::size_t connectionsAccepted() const;
  void stop();

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
  std::thread thread_;
};

}  // namespace emulation
}  // namespace dormant_tree_modeling
