#include "dormant_tree_modeling/common/tcp_connection.h"

#include <array>
#include <boost/asio.hpp>
#include <chrono>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {

namespace asio = boost::asio;
using tcp = asio::ip::tcp;

struct TcpConnection::Impl {
  asio::io_context io;
  tcp::socket socket{io};
  std::array<char, 65536> buffer{};

  // Runs the started operation until it completes or the timeout passes. On timeout the
  // operation is cancelled and its handler still runs: with operation_aborted, or with its
  // result if it completed in the meantime (so no received byte is lost).
  void runFor(double timeout_s, const bool& done) {
    io.restart();
    io.run_for(std::chrono::duration_cast<std::chrono::nanoseconds>(
        std::chrono::duration<double>(std::max(0.0, timeout_s))));
    if (done)
      return;
    boost::system::error_code ignored;
    socket.cancel(ignored);
    io.restart();
    io.run();
  }
};

TcpConnection::TcpConnection() : impl_(std::make_unique<Impl>()) {}

TcpConnection::~TcpConnection() {
  close();
}

void TcpConnection::connect(const std::string& host, int port, double timeout_s) {
  close();
  const std::string where = host + ":" + std::to_string(port);
  boost::system::error_code ec;
  tcp::resolver resolver(impl_->io);
  const auto endpoints = resolver.resolve(host, std::to_string(port), ec);
  if (ec)
    throw Error(ErrorCode::IO_FAILURE, "cannot resolve " + where + ": " + ec.message());
  bool done = false;
  boost::system::error_code result;
  asio::async_connect(impl_->socket, endpoints,
                      [&](boost::system::error_code e, const tcp::endpoint&) {
                        result = e;
                        done = true;
                      });
  impl_->runFor(timeout_s, done);
  if (result == asio::error::operation_aborted) {
    close();
    throw Error(ErrorCode::IO_FAILURE,
                "no connection to " + where + " within " + std::to_string(timeout_s) + " s");
  }
  if (result) {
    close();
    throw Error(ErrorCode::IO_FAILURE, "cannot connect to " + where + ": " + result.message());
  }
  boost::system::error_code ignored;
  impl_->socket.set_option(tcp::no_delay(true), ignored);
  impl_->socket.set_option(asio::socket_base::keep_alive(true), ignored);
}

void TcpConnection::send(const std::string& bytes, double timeout_s) {
  if (!isOpen())
    throw Error(ErrorCode::IO_FAILURE, "send on a closed connection");
  bool done = false;
  boost::system::error_code result;
  asio::async_write(impl_->socket, asio::buffer(bytes),
                    [&](boost::system::error_code e, std::size_t) {
                      result = e;
                      done = true;
                    });
  impl_->runFor(timeout_s, done);
  if (result) {
    const std::string why = result == asio::error::operation_aborted ? "timeout" : result.message();
    close();
    throw Error(ErrorCode::IO_FAILURE, "send failed: " + why);
  }
}

std::string TcpConnection::receiveSome(double timeout_s) {
  if (!isOpen())
    throw Error(ErrorCode::IO_FAILURE, "receive on a closed connection");
  bool done = false;
  boost::system::error_code result;
  std::size_t received = 0;
  impl_->socket.async_read_some(asio::buffer(impl_->buffer),
                                [&](boost::system::error_code e, std::size_t n) {
                                  result = e;
                                  received = n;
                                  done = true;
                                });
  impl_->runFor(timeout_s, done);
  if (result == asio::error::operation_aborted)
    return {};
  if (result) {
    const std::string why =
        result == asio::error::eof ? "the device closed the connection" : result.message();
    close();
    throw Error(ErrorCode::IO_FAILURE, why);
  }
  return std::string(impl_->buffer.data(), received);
}

void TcpConnection::close() {
  if (!impl_->socket.is_open())
    return;
  boost::system::error_code ignored;
  impl_->socket.shutdown(tcp::socket::shutdown_both, ignored);
  impl_->socket.close(ignored);
}

bool TcpConnection::isOpen() const {
  return impl_->socket.is_open();
}

}  // namespace dormant_tree_modeling
