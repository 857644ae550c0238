#include "dormant_tree_modeling/emulation/ensemble_server.h"

#include <atomic>
#include <boost/asio.hpp>
#include <chrono>
#include <deque>
#include <list>

#include "dormant_tree_modeling/aerotech/ascii_protocol.h"
#include "dormant_tree_modeling/common/error.h"
#include "listen.h"

namespace dormant_tree_modeling {
namespace emulation {

using namespace aerotech;  // the emulator speaks the protocol the real client speaks

namespace asio = boost::asio;
using tcp = asio::ip::tcp;
using Clock = std::chrono::steady_clock;

struct EnsembleServer::Impl {
  struct Session : std::enable_shared_from_this<Session> {
    Session(Impl& server, tcp::socket socket)
        : server(server),
          socket(std::move(socket)),
          reply_timer(server.io),
          idle_timer(server.io) {}
    Impl& server;
    tcp::socket socket;
    asio::steady_timer reply_timer, idle_timer;
    LineFramer framer;
    std::array<char, 1024> buffer{};
    std::deque<EnsembleResponse> pending;  // replies in command order
    bool sending = false, open = true;
    std::size_t commands = 0;

    void start() {
      armIdle();
      read();
    }
    void armIdle() {
      const double idle = server.controller->faults().idle_timeout_s;
      if (idle <= 0)
        return;
      idle_timer.expires_after(
          std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(idle)));
      auto self = shared_from_this();
      idle_timer.async_wait([self](boost::system::error_code ec) {
        if (!ec)
          self->close();
      });
    }
    void read() {
      auto self = shared_from_this();
      socket.async_read_some(
          asio::buffer(buffer), [self](boost::system::error_code ec, std::size_t n) {
            if (ec || !self->open) {
              self->close();
              return;
            }
            self->armIdle();
            self->framer.feed(self->buffer.data(), n);
            while (auto line = self->framer.next()) {
              self->pending.push_back(self->server.controller->handle(*line, self->server.now()));
              ++self->commands;
            }
            self->flush();
            self->read();
          });
    }
    // Sends the due replies in order; waits for the first one not yet due.
    void flush() {
      if (sending || pending.empty() || !open)
        return;
      const double wait = pending.front().ready_at_s - server.now();
      auto self = shared_from_this();
      if (wait > 0) {
        sending = true;
        reply_timer.expires_after(
            std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(wait)));
        reply_timer.async_wait([self](boost::system::error_code ec) {
          self->sending = false;
          if (!ec)
            self->flush();
        });
        return;
      }
      sending = true;
      auto line = std::make_shared<std::string>(pending.front().line + "\n");
      pending.pop_front();
      asio::async_write(
          socket, asio::buffer(*line), [self, line](boost::system::error_code ec, std::size_t) {
            self->sending = false;
            if (ec) {
              self->close();
              return;
            }
            const std::size_t drop = self->server.controller->faults().drop_after_commands;
            if (drop > 0 && ++self->server.replies == drop) {
              self->close();
              return;
            }
            self->flush();
          });
    }
    void close() {
      if (!open)
        return;
      open = false;
      boost::system::error_code ignored;
      socket.shutdown(tcp::socket::shutdown_both, ignored);
      socket.close(ignored);
      reply_timer.cancel();
      idle_timer.cancel();
      server.sessions.remove(shared_from_this());
    }
  };

  Impl(std::shared_ptr<EmulatedEnsemble> c) : controller(std::move(c)), acceptor(io) {}

  double now() const { return std::chrono::duration<double>(Clock::now() - start).count(); }

  void accept() {
    acceptor.async_accept([this](boost::system::error_code ec, tcp::socket socket) {
      if (ec)
        return;
      ++accepted;
      boost::system::error_code ignored;
      socket.set_option(tcp::no_delay(true), ignored);
      auto s = std::make_shared<Session>(*this, std::move(socket));
      sessions.push_back(s);
      s->start();
      accept();
    });
  }

  asio::io_context io;
  std::shared_ptr<EmulatedEnsemble> controller;
  tcp::acceptor acceptor;
  std::list<std::shared_ptr<Session>> sessions;
  Clock::time_point start = Clock::now();
  std::size_t replies = 0;
  std::atomic<std::size_t> accepted{0};
  int bound = -1;
};

EnsembleServer::EnsembleServer(std::shared_ptr<EmulatedEnsemble> controller,
                               const std::string& address, int port)
    : impl_(std::make_unique<Impl>(std::move(controller))) {
  if (!impl_->controller)
    throw Error(ErrorCode::INVALID_ARGUMENT, "the Ensemble server needs a controller");
  auto& a = impl_->acceptor;
  listenOn(a, address, port, "Ensemble emulator");
  impl_->bound = a.local_endpoint().port();
  impl_->accept();
  thread_ = std::thread([this] { impl_->io.run(); });
}

EnsembleServer::~EnsembleServer() {
  stop();
}

void EnsembleServer::stop() {
  if (!thread_.joinable())
    return;
  asio::post(impl_->io, [this] {
    boost::system::error_code ignored;
    impl_->acceptor.close(ignored);
    auto all = impl_->sessions;
    for (auto& s : all)
      s->close();
    impl_->io.stop();
  });
  thread_.join();
}

int EnsembleServer::port() const {
  return impl_->bound;
}

double EnsembleServer::now() const {
  return impl_->now();
}

std::size_t EnsembleServer::connectionsAccepted() const {
  return impl_->accepted;
}

}  // namespace emulation
}  // namespace dormant_tree_modeling
