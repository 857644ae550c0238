#pragma once

#include <memory>
#include <string>

namespace dormant_tree_modeling {

/// @brief A blocking TCP client connection in which every operation has a deadline, so a
/// driver thread can never hang on a dead device (LMS111, Aerotech). Boost.Asio stays out of
/// this header.
class TcpConnection {
 public:
  TcpConnection();
  ~TcpConnection();
  TcpConnection(const TcpConnection&) = delete;
  TcpConnection& operator=(const TcpConnection&) = delete;

  /// @brief Connect, closing any previous connection first.
  /// @throws Error IO_FAILURE naming the address and the reason (refused, timeout, no route)
  void connect(const std::string& host, int port, double timeout_s);
  /// @brief Write all bytes. @throws Error IO_FAILURE on error or timeout (the connection is
  /// closed then)
  void send(const std::string& bytes, double timeout_s);
  /// @brief The bytes that arrive within the timeout: empty when none did.
  /// @throws Error IO_FAILURE when the peer closed the connection or the socket failed
  std::string receiveSome(double timeout_s);
  /// @brief Close (idempotent).
  void close();
  bool isOpen() const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace dormant_tree_modeling
