#include "dormant_tree_modeling/lms111/driver.h"

#include <chrono>
#include <cmath>
#include <sstream>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/tcp_connection.h"
#include "dormant_tree_modeling/lms111/cola_fields.h"
#include "dormant_tree_modeling/lms111/requests.h"

namespace dormant_tree_modeling {
namespace lms111 {

namespace {

constexpr double STOP_REPLY_TIMEOUT_S = 0.5;
constexpr double MIN_SCAN_TIMEOUT_S = 0.2;
// Real devices report their angles a few 1/10000 deg off the nominal (an LMS111 answers its
// range as -44.9997 ... 224.9997 deg): scans are the configured ones within this, a small
// fraction of the finest step (0.25 deg).
constexpr std::int32_t ANGLE_TOLERANCE_UNITS = 100;

double steadySeconds() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

/// The device answered a request with sFA.
struct DeviceRefusal : Error {
  DeviceRefusal(const std::string& command, int code)
      : Error(ErrorCode::IO_FAILURE, "the device refused " + command + " with sFA " +
                                         std::to_string(code) + ": " + describeSfaError(code)),
        code(code) {}
  int code;
};

}  // namespace

int DriverConfig::beamCount() const {
  return static_cast<int>((stopUnits() - startUnits()) /
                          static_cast<std::int64_t>(resolutionUnits())) +
         1;
}
std::uint32_t DriverConfig::frequencyUnits() const {
  return static_cast<std::uint32_t>(std::lround(scan_frequency_hz * 100.0));
}
std::uint32_t DriverConfig::resolutionUnits() const {
  return static_cast<std::uint32_t>(std::lround(angular_resolution_deg * 10000.0));
}
std::int32_t DriverConfig::startUnits() const {
  return static_cast<std::int32_t>(std::lround(start_angle_deg * 10000.0));
}
std::int32_t DriverConfig::stopUnits() const {
  return static_cast<std::int32_t>(std::lround(stop_angle_deg * 10000.0));
}

const char* driverStateName(DriverState state) {
  switch (state) {
    case DriverState::STOPPED:
      return "stopped";
    case DriverState::CONNECTING:
      return "connecting";
    case DriverState::CONFIGURING:
      return "configuring";
    case DriverState::STREAMING:
      return "streaming";
    case DriverState::BACKING_OFF:
      return "backing off";
  }
  return "?";
}

// One connection's conversation with the device: requests, replies, the stream.
class Lms111Driver::Session {
 public:
  explicit Session(Lms111Driver& driver)
      : d_(driver), c_(driver.config_), framer_(makeFramer(c_.protocol)) {}

  void connect() { connection_.connect(c_.host, c_.port, c_.connect_timeout_s); }

  // Sends a request payload, waits for its reply (the request's reply type and name) and hands
  // back a reader positioned at the reply's arguments. Events (`sSN`: scans still in flight,
  // input/output states, field records a previous client subscribed) are passed over.
  std::unique_ptr<FieldReader> request(const std::string& payload, double timeout_s = -1.0) {
    const auto words = makeReader(c_.protocol, payload);
    const std::string type = words->word("command type");
    const std::string name = words->word("command");
    const double timeout = timeout_s > 0 ? timeout_s : c_.reply_timeout_s;
    connection_.send(frame(c_.protocol, payload), timeout);
    const std::string expected = replyTypeOf(type);
    const double deadline = steadySeconds() + timeout;
    for (;;) {
      const auto reply = nextPayload(deadline - steadySeconds());
      if (!reply) {
        throw Error(ErrorCode::IO_FAILURE, "no reply to " + type + " " + name + " within " +
                                               std::to_string(timeout) + " s");
      }
      if (const auto code = sfaCode(c_.protocol, *reply))
        throw DeviceRefusal(type + " " + name, *code);
      auto r = makeReader(c_.protocol, *reply);
      const std::string got_type = r->word("reply type");
      if (got_type == "sSN")
        continue;
      const std::string got_name = r->word("reply name");
      if (got_type == expected && got_name == name)
        return r;
      d_.log(1, "ignored an unexpected reply '" + printableBytes(got_type + " " + got_name) +
                    "' to " + type + " " + name);
    }
  }

  // The next framed payload within the timeout, or nothing.
  std::optional<std::string> nextPayload(double timeout_s) {
    const double deadline = steadySeconds() + std::max(0.0, timeout_s);
    for (;;) {
      if (auto p = framer_->next())
        return p;
      const double left = deadline - steadySeconds();
      if (left <= 0 || d_.stopping_)
        return std::nullopt;
      // Short slices, so that stop() is honoured promptly.
      const std::string bytes = connection_.receiveSome(std::min(left, 0.1));
      framer_->feed(bytes.data(), bytes.size());
      const std::size_t discarded = framer_->discarded();
      if (discarded > discarded_) {
        std::lock_guard<std::mutex> lock(d_.mutex_);
        d_.stats_.discarded_bytes += discarded - discarded_;
      }
      discarded_ = discarded;
    }
  }

  void configure() {
    readDeviceIdent();
    auto login = request(loginRequest(c_.protocol));
    if (login->unsignedValue("result", 8) != 1)
      throw Error(ErrorCode::IO_FAILURE, "the device refused the authorised-client login");
    setScanConfig();
    request(outputRangeRequest(c_.protocol, area()));
    ScanDataOutput output;
    output.rssi = c_.rssi;  // no time block: the µs clock is what we map
    request(scanDataConfigRequest(c_.protocol, output));
    request(plainRequest(c_.protocol, "sMN", "LMCstartmeas"));
    // Run leaves the authorised level and applies the configuration.
    request(plainRequest(c_.protocol, "sMN", "Run"));
    verifyScanConfig();
    request(streamRequest(c_.protocol, true));
  }

  void readDeviceIdent() {
    auto r = request(plainRequest(c_.protocol, "sRN", "DeviceIdent"));
    const auto n = r->unsignedValue("name length", 16);
    std::string ident = r->characters("name", n);
    const auto m = r->unsignedValue("version length", 16);
    ident += " " + r->characters("version", m);
    std::lock_guard<std::mutex> lock(d_.mutex_);
    d_.stats_.device_ident = printableBytes(ident);
  }

  ScanArea area() const {
    ScanArea a;
    a.resolution = c_.resolutionUnits();
    a.start_angle = c_.startUnits();
    a.stop_angle = c_.stopUnits();
    return a;
  }

  // Some firmware refuses mLMPsetscancfg (sFA 8 or 11) although it already runs the asked
  // configuration; others answer sFA 4 to the first configuration after power-up. Read back
  // what the device runs and carry on only if it matches.
  void setScanConfig() {
    try {
      auto r = request(setScanConfigRequest(c_.protocol, c_.frequencyUnits(), area()));
      const auto result = r->unsignedValue("result", 8);
      if (result != 0) {
        static const char* WHY[] = {"", "frequency not supported", "resolution not supported",
                                    "frequency and resolution not supported",
                                    "scan area not supported"};
        throw Error(ErrorCode::INVALID_ARGUMENT,
                    std::string("the device rejected the scan configuration: ") +
                        (result < 5 ? WHY[result] : "error " + std::to_string(result)));
      }
    } catch (const DeviceRefusal& e) {
      d_.log(1, std::string(e.what()) + "; checking whether it already runs the asked one");
      verifyScanConfig();
    }
  }

  // The device's state, for a message: best effort, as the device may be what failed.
  std::string stateForMessage() {
    try {
      auto r = request(plainRequest(c_.protocol, "sRN", "STlms"), STOP_REPLY_TIMEOUT_S);
      return deviceStateName(static_cast<int>(r->unsignedValue("state", 16)));
    } catch (const Error&) {
      return "unknown";
    }
  }

  void verifyScanConfig() {
    auto r = request(plainRequest(c_.protocol, "sRN", "LMPscancfg"));
    const auto frequency = r->unsignedValue("scan frequency");
    r->unsignedValue("sectors", 16);
    const auto resolution = r->unsignedValue("resolution");
    if (frequency != c_.frequencyUnits() || resolution != c_.resolutionUnits()) {
      std::ostringstream m;
      m << "the device runs " << frequency / 100.0 << " Hz / " << resolution / 10000.0
        << " deg, not the requested " << c_.scan_frequency_hz << " Hz / "
        << c_.angular_resolution_deg << " deg";
      throw Error(ErrorCode::INVALID_ARGUMENT, m.str());
    }
  }

  // The scans themselves are the authority: LMPoutputRange can misreport the resolution.
  void verifyScan(const ScanTelegram& s) const {
    const ScanChannel* dist = s.channel("DIST1");
    std::ostringstream m;
    if (!dist) {
      m << "the scans carry no DIST1 channel";
    } else if (s.scan_frequency != c_.frequencyUnits() ||
               dist->angular_step != c_.resolutionUnits()) {
      m << "the device streams " << s.scanFrequencyHz() << " Hz / " << dist->stepDeg()
        << " deg, not the requested " << c_.scan_frequency_hz << " Hz / "
        << c_.angular_resolution_deg << " deg";
    } else if (std::abs(dist->start_angle - c_.startUnits()) > ANGLE_TOLERANCE_UNITS ||
               static_cast<int>(dist->values.size()) != c_.beamCount()) {
      m << "the device streams " << dist->values.size() << " beams from " << dist->startAngleDeg()
        << " deg, not the requested " << c_.beamCount() << " from " << c_.start_angle_deg << " deg";
    } else if (c_.rssi && !s.channel("RSSI1")) {
      m << "the scans carry no RSSI1 channel although it was requested";
    } else {
      return;
    }
    throw Error(ErrorCode::INVALID_ARGUMENT, m.str());
  }

  // Scans until stopped. The first scan may take the motor's spin-up (ready_timeout_s): a
  // device sends scans only once it is ready for measurement, which is the readiness test that
  // does not depend on how a firmware lays out `STlms`.
  void stream() {
    const double period = 1.0 / c_.scan_frequency_hz;
    const double timeout = std::max(MIN_SCAN_TIMEOUT_S, c_.scan_timeout_periods * period);
    bool verified = false;
    std::optional<std::uint16_t> last_counter;
    while (!d_.stopping_) {
      const auto payload = nextPayload(verified ? timeout : c_.ready_timeout_s);
      if (d_.stopping_)
        return;
      if (!payload && !verified) {
        throw Error(ErrorCode::IO_FAILURE,
                    "no scan within " + std::to_string(c_.ready_timeout_s) +
                        " s of switching the stream on (device state: " + stateForMessage() + ")");
      }
      if (!payload) {
        throw Error(ErrorCode::IO_FAILURE, "no scan within " + std::to_string(timeout) +
                                               " s (device silent or connection half-open)");
      }
      const double received = d_.clock_();
      if (!isScanTelegram(*payload)) {
        noteOtherTelegram(*payload);
        continue;
      }
      ScanTelegram scan;
      try {
        scan = parseScanTelegram(*payload, c_.protocol);
      } catch (const Error& e) {
        std::lock_guard<std::mutex> lock(d_.mutex_);
        ++d_.stats_.parse_errors;
        d_.stats_.last_error = std::string("parse error: ") + e.what();
        continue;
      }
      if (!verified) {
        verifyScan(scan);
        verified = true;
        d_.last_logged_error_.clear();  // the next failure is news again
        std::lock_guard<std::mutex> lock(d_.mutex_);
        ++d_.stats_.connects;
      }
      d_.setState(DriverState::STREAMING);
      if (d_.clock_mapper_.observe(scan.time_of_transmission_us, received))
        d_.log(1, "the device clock restarted (device reboot?): clock mapping reset");
      StampedScan out;
      out.received_s = received;
      out.stamp_s = d_.clock_mapper_.toHost(scan.time_since_startup_us).value_or(received);
      {
        std::lock_guard<std::mutex> lock(d_.mutex_);
        ++d_.stats_.scans;
        if (last_counter) {
          const std::uint16_t step = static_cast<std::uint16_t>(scan.scan_counter - *last_counter);
          if (step > 1)
            d_.stats_.scan_gaps += step - 1;
        }
        d_.stats_.device_status = scan.device_status;
      }
      last_counter = scan.scan_counter;
      out.telegram = std::move(scan);
      if (d_.on_scan_)
        d_.on_scan_(out);
    }
  }

  // Best effort: the device may be gone already.
  void stopStream() {
    if (!connection_.isOpen())
      return;
    try {
      request(streamRequest(c_.protocol, false), STOP_REPLY_TIMEOUT_S);
    } catch (const Error&) {
    }
    connection_.close();
  }

 private:
  // Events (sSN LIDoutputstate, LIDinputstate, LFErec, ...) are counted; an sFA while
  // streaming is logged.
  void noteOtherTelegram(const std::string& payload) {
    if (payload.compare(0, 3, "sSN") == 0) {
      std::lock_guard<std::mutex> lock(d_.mutex_);
      ++d_.stats_.events;
      return;
    }
    if (payload.compare(0, 3, "sFA") == 0)
      d_.log(1, "the device sent '" + printableBytes(payload) + "' while streaming");
  }

  Lms111Driver& d_;
  const DriverConfig& c_;
  TcpConnection connection_;
  std::unique_ptr<Framer> framer_;
  std::size_t discarded_ = 0;
};

Lms111Driver::Lms111Driver(DriverConfig config, ScanCallback on_scan, LogCallback log,
                           ClockFunction clock)
    : config_(std::move(config)),
      on_scan_(std::move(on_scan)),
      log_(std::move(log)),
      clock_(std::move(clock)) {
  config_.validate();
  if (!clock_) {
    clock_ = [] {
      return std::chrono::duration<double>(std::chrono::system_clock::now().time_since_epoch())
          .count();
    };
  }
}

Lms111Driver::~Lms111Driver() {
  stop();
}

void Lms111Driver::start() {
  if (thread_.joinable())
    return;
  stopping_ = false;
  thread_ = std::thread([this] { run(); });
}

void Lms111Driver::stop() {
  stopping_ = true;
  if (thread_.joinable())
    thread_.join();
  setState(DriverState::STOPPED);
}

DriverStatistics Lms111Driver::statistics() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return stats_;
}

void Lms111Driver::setState(DriverState state) {
  std::lock_guard<std::mutex> lock(mutex_);
  stats_.state = state;
}

void Lms111Driver::log(int severity, const std::string& message) {
  if (log_)
    log_(severity, message);
}

bool Lms111Driver::sleepFor(double seconds) {
  const double end = steadySeconds() + seconds;
  while (!stopping_) {
    const double left = end - steadySeconds();
    if (left <= 0)
      return true;
    std::this_thread::sleep_for(std::chrono::duration<double>(std::min(left, 0.05)));
  }
  return false;
}

void Lms111Driver::run() {
  double backoff = config_.reconnect_min_s;
  const std::string where = config_.host + ":" + std::to_string(config_.port) + " (" +
                            protocolName(config_.protocol) + ")";
  while (!stopping_) {
    Session session(*this);
    try {
      setState(DriverState::CONNECTING);
      session.connect();
      setState(DriverState::CONFIGURING);
      session.configure();
      std::ostringstream configured;
      configured << "LMS111 at " << where << " (" << statistics().device_ident
                 << ") configured: " << config_.scan_frequency_hz << " Hz, "
                 << config_.angular_resolution_deg << " deg, " << config_.beamCount() << " beams";
      log(0, configured.str());
      // A device that rebooted has a new clock; a mapping across connections is not trusted.
      clock_mapper_.reset();
      session.stream();
      session.stopStream();
    } catch (const Error& e) {
      session.stopStream();
      if (stopping_)
        break;
      const bool streamed = statistics().state == DriverState::STREAMING;
      if (streamed)
        backoff = config_.reconnect_min_s;
      {
        std::lock_guard<std::mutex> lock(mutex_);
        ++stats_.failures;
        stats_.last_error = e.what();
      }
      // One message per kind of failure, not one per retry.
      if (e.what() != last_logged_error_) {
        log(2, "LMS111 at " + where + ": " + e.what() + "; retrying in " + std::to_string(backoff) +
                   " s");
        last_logged_error_ = e.what();
      }
      setState(DriverState::BACKING_OFF);
      if (!sleepFor(backoff))
        break;
      backoff = std::min(config_.reconnect_max_s, backoff * 2.0);
    }
  }
  setState(DriverState::STOPPED);
}

}  // namespace lms111
}  // namespace dormant_tree_modeling
