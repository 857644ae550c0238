#include "dormant_tree_modeling/emulation/lms111_server.h"

#include <boost/asio.hpp>
#include <chrono>
#include <deque>
#include <list>

#include "dormant_tree_modeling/common/error.h"
#include "listen.h"

namespace dormant_tree_modeling {
namespace emulation {

using namespace lms111;  // the emulator speaks the protocol the real driver speaks

namespace asio = boost::asio;
using tcp = asio::ip::tcp;
using Clock = std::chrono::steady_clock;

namespace {

// Pause between the pieces of a trickled telegram.
constexpr auto TRICKLE_PAUSE = std::chrono::milliseconds(1);

}  // namespace

struct LmsServer::Impl {
  struct Session : std::enable_shared_from_this<Session> {
    Session(Impl& server, tcp::socket socket, Protocol protocol)
        : server(server),
          socket(std::move(socket)),
          timer(server.io),
          framer(makeFramer(protocol)) {
      state.protocol = protocol;
    }
    Impl& server;
    tcp::socket socket;
    asio::steady_timer timer;  // trickle pauses
    std::unique_ptr<Framer> framer;
    LmsSession state;
    std::array<char, 4096> buffer{};
    std::deque<std::string> queue;
    std::size_t offset = 0;  // bytes of queue.front() already written
    bool writing = false;
    bool open = true;

    void read() {
      auto self = shared_from_this();
      socket.async_read_some(asio::buffer(buffer), [self](boost::system::error_code ec,
                                                          std::size_t n) {
        if (ec || !self->open) {
          self->close();
          return;
        }
        self->framer->feed(self->buffer.data(), n);
        while (auto payload = self->framer->next()) {
          if (self->server.stalled())
            continue;  // a stalled device answers nothing
          for (auto& reply : self->server.device->handle(*payload, self->state, self->server.now()))
            self->send(frame(self->state.protocol, reply));
        }
        self->read();
      });
    }

    void send(std::string bytes) {
      queue.push_back(std::move(bytes));
      if (!writing)
        write();
    }

    void write() {
      if (queue.empty() || !open) {
        writing = false;
        return;
      }
      writing = true;
      const std::string& front = queue.front();
      const std::size_t piece =
          server.device->faults().trickle_bytes > 0
              ? std::min(server.device->faults().trickle_bytes, front.size() - offset)
              : front.size() - offset;
      auto self = shared_from_this();
      asio::async_write(
          socket, asio::buffer(front.data() + offset, piece),
          [self, piece](boost::system::error_code ec, std::size_t) {
            if (ec) {
              self->close();
              return;
            }
            self->offset += piece;
            if (self->offset == self->queue.front().size()) {
              self->queue.pop_front();
              self->offset = 0;
            }
            if (self->server.device->faults().trickle_bytes > 0) {
              self->timer.expires_after(TRICKLE_PAUSE);
              self->timer.async_wait([self](boost::system::error_code) { self->write(); });
            } else {
              self->write();
            }
          });
    }

    void close() {
      if (!open)
        return;
      open = false;
      boost::system::error_code ignored;
      socket.shutdown(tcp::socket::shutdown_both, ignored);
      socket.close(ignored);
      timer.cancel();
      server.sessions.remove(shared_from_this());
    }
  };

  Impl(std::shared_ptr<EmulatedLms111> device, LmsServerConfig options)
      : device(std::move(device)), options(std::move(options)), scan_timer(io), restart_timer(io) {}

  double now() const { return std::chrono::duration<double>(Clock::now() - start).count(); }
  bool stalled() const { return now() < stalled_until; }

  void listen() {
    for (int p = 0; p < 2; ++p) {
      const int port = p == 0 ? options.cola_a_port : options.cola_b_port;
      if (port < 0)
        continue;
      // After a restart, listen on the port bound at the start.
      const int bind_port = bound[p] > 0 ? bound[p] : port;
      auto& acceptor = acceptors[p];
      acceptor = std::make_unique<tcp::acceptor>(io);
      listenOn(*acceptor, options.address, bind_port, "LMS111 emulator");
      bound[p] = acceptor->local_endpoint().port();
      accept(p);
    }
  }

  void accept(int p) {
    acceptors[p]->async_accept([this, p](boost::system::error_code ec, tcp::socket socket) {
      if (ec)
        return;  // closed by stop or restart
      ++accepted;
      boost::system::error_code ignored;
      socket.set_option(tcp::no_delay(true), ignored);
      auto session = std::make_shared<Session>(*this, std::move(socket),
                                               p == 0 ? Protocol::COLA_A : Protocol::COLA_B);
      sessions.push_back(session);
      session->read();
      accept(p);
    });
  }

  void closeAll() {
    for (auto& a : acceptors) {
      if (a) {
        boost::system::error_code ignored;
        a->close(ignored);
      }
    }
    auto all = sessions;
    for (auto& s : all)
      s->close();
  }

  void scheduleScan() {
    next_scan += std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(device->scanPeriod()));
    // Catch up without a burst after a stall or a reboot.
    if (next_scan < Clock::now())
      next_scan = Clock::now();
    scan_timer.expires_at(next_scan);
    scan_timer.async_wait([this](boost::system::error_code ec) {
      if (ec)
        return;
      scan();
      scheduleScan();
    });
  }

  void scan() {
    if (restarting || stalled())
      return;
    bool anyone = false;
    for (const auto& s : sessions)
      anyone = anyone || s->state.streaming;
    if (!anyone)
      return;
    // A real device's scans are exactly periodic: stamp with the schedule, not the wake-up.
    const auto telegram =
        device->nextScan(std::chrono::duration<double>(next_scan - start).count());
    if (!telegram)
      return;
    const LmsFaults& faults = device->faults();
    ++scans_sent;
    std::string framed[2];
    auto all = sessions;
    for (auto& s : all) {
      if (!s->state.streaming)
        continue;
      std::string& bytes = framed[s->state.protocol == Protocol::COLA_A ? 0 : 1];
      if (bytes.empty()) {
        bytes = frame(s->state.protocol, encodeScanTelegram(*telegram, s->state.protocol));
        if (faults.corrupt_every > 0 && scans_sent % faults.corrupt_every == 0)
          bytes[bytes.size() / 2] ^= 0x5A;
      }
      s->send(bytes);
      ++sent;
    }
    // A recording's events (LIDoutputstate, LFErec, ...) come between the scans, as a real
    // device's do once a client subscribed them.
    if (auto event = device->nextEvent(Protocol::COLA_B)) {
      const std::string framed_event = frame(Protocol::COLA_B, *event);
      for (auto& s : all) {
        if (s->state.streaming && s->state.protocol == Protocol::COLA_B)
          s->send(framed_event);
      }
    }
    if (faults.drop_after > 0 && scans_sent == faults.drop_after) {
      for (auto& s : all)
        s->close();
    }
    if (faults.stall_after > 0 && scans_sent == faults.stall_after)
      stalled_until = now() + faults.stall_seconds;
    if (faults.restart_after > 0 && scans_sent == faults.restart_after)
      restart();
  }

  void restart() {
    restarting = true;
    closeAll();
    restart_timer.expires_after(std::chrono::duration_cast<Clock::duration>(
        std::chrono::duration<double>(device->faults().restart_seconds)));
    restart_timer.async_wait([this](boost::system::error_code ec) {
      if (ec)
        return;
      device->powerUp(now());
      restarting = false;
      scans_sent = 0;
      try {
        listen();
      } catch (const Error&) {
        // The port was taken while "rebooting": stay down, as a device that fails to boot.
      }
    });
  }

  asio::io_context io;
  std::shared_ptr<EmulatedLms111> device;
  LmsServerConfig options;
  std::unique_ptr<tcp::acceptor> acceptors[2];
  int bound[2] = {-1, -1};
  std::list<std::shared_ptr<Session>> sessions;
  asio::steady_timer scan_timer, restart_timer;
  Clock::time_point start = Clock::now();
  Clock::time_point next_scan = start;
  double stalled_until = -1.0;
  bool restarting = false;
  std::size_t scans_sent = 0;
  std::atomic<std::size_t> sent{0}, accepted{0};
};

LmsServer::LmsServer(std::shared_ptr<EmulatedLms111> device, LmsServerConfig options)
    : impl_(std::make_unique<Impl>(std::move(device), std::move(options))) {
  if (!impl_->device)
    throw Error(ErrorCode::INVALID_ARGUMENT, "the emulator server needs a device");
  impl_->device->powerUp(impl_->now());
  impl_->listen();
  impl_->scheduleScan();
  thread_ = std::thread([this] { impl_->io.run(); });
}

LmsServer::~LmsServer() {
  stop();
}

void LmsServer::stop() {
  if (!thread_.joinable())
    return;
  asio::post(impl_->io, [this] {
    impl_->closeAll();
    impl_->scan_timer.cancel();
    impl_->restart_timer.cancel();
    impl_->io.stop();
  });
  thread_.join();
}

int LmsServer::colaAPort() const {
  return impl_->bound[0];
}

int LmsServer::colaBPort() const {
  return impl_->bound[1];
}

std::size_t LmsServer::telegramsSent() const {
  return impl_->sent;
}

std::size_t LmsServer::connectionsAccepted() const {
  return impl_->accepted;
}

}  // namespace emulation
}  // namespace dormant_tree_modeling
