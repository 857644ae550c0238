#include "dormant_tree_modeling/emulation/lms111_emulator.h"

#include <cmath>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace emulation {

using namespace lms111;  // the emulator speaks the protocol the real driver speaks

namespace {

// The request names the device does not know at all answer this (SOPAS "unknown command").
constexpr int SFA_UNKNOWN_COMMAND = SFA_UNKNOWN_NAMESERVER_COMMAND;
// The one echo the emulated device measures (output channel mask of LMDscandatacfg).
constexpr std::uint64_t FIRST_ECHO = 1;

// mLMPsetscancfg result codes.
constexpr int SCANCFG_OK = 0;
constexpr int SCANCFG_BAD_FREQUENCY = 1;
constexpr int SCANCFG_BAD_RESOLUTION = 2;
constexpr int SCANCFG_BAD_BOTH = 3;
constexpr int SCANCFG_BAD_AREA = 4;

constexpr std::int32_t MIN_ANGLE = -450000;  // 1/10000 deg
constexpr std::int32_t MAX_ANGLE = 2250000;

// Thrown inside dispatch to answer with an sFA code.
struct SfaReply {
  int code;
};

// A request with more fields than its layout holds is refused as the device does.
void expectEnd(const FieldReader& r) {
  if (!r.atEnd())
    throw SfaReply{SFA_BUFFER_OVERFLOW};
}

// A field the layout reserves (the high byte of the output channel and of the encoder setting).
void expectZero(std::uint64_t value) {
  if (value != 0)
    throw SfaReply{SFA_INVALID_DATA};
}

bool validPair(std::uint32_t frequency, std::uint32_t resolution) {
  // The LMS111 pairs 25 Hz with 0.25 deg and 50 Hz with 0.5 deg.
  return (frequency == 2500 && resolution == 2500) || (frequency == 5000 && resolution == 5000);
}

bool validArea(std::int32_t start, std::int32_t stop, std::uint32_t resolution) {
  return start >= MIN_ANGLE && stop <= MAX_ANGLE && start < stop && resolution > 0 &&
         (stop - start) % static_cast<std::int32_t>(resolution) == 0;
}

void writeScanArea(FieldWriter& w, const DeviceScanConfig& c, std::int32_t angle_error = 0) {
  w.unsignedValue(c.resolution);
  w.signedValue(c.start_angle + angle_error);
  w.signedValue(c.stop_angle - angle_error);
}

// sWN LMDscandatacfg as the device lays it out: output channel (echo mask, reserved), remission,
// remission resolution, unit, encoder (setting, reserved), position, device name, comment,
// time, output interval (16 bit); the LMS111 has no position block and no encoder here.
DataOutputConfig readDataOutputConfig(FieldReader& r) {
  const auto echo_mask = r.unsignedValue("output channel", 8);
  expectZero(r.unsignedValue("output channel (reserved)", 8));
  DataOutputConfig o;
  o.rssi = r.unsignedValue("remission", 8) != 0;
  const auto resolution = r.unsignedValue("remission resolution", 8);
  o.rssi_16bit = resolution == 1;
  const auto unit = r.unsignedValue("unit", 8);
  const auto encoder = r.unsignedValue("encoder", 8);
  expectZero(r.unsignedValue("encoder (reserved)", 8));
  const auto position = r.unsignedValue("position", 8);
  o.device_name = r.unsignedValue("device name", 8) != 0;
  o.comment = r.unsignedValue("comment", 8) != 0;
  o.time_stamp = r.unsignedValue("time", 8) != 0;
  o.output_interval = static_cast<std::uint16_t>(r.unsignedValue("output interval", 16));
  expectEnd(r);
  if (echo_mask != FIRST_ECHO || resolution > 1 || unit != 0 || encoder != 0 || position != 0 ||
      o.output_interval == 0)
    throw SfaReply{SFA_INVALID_DATA};
  return o;
}

}  // namespace

void LmsFaults::addSfa(const std::string& spec) {
  const auto a = spec.find(':');
  if (a == std::string::npos || a == 0) {
    throw Error(ErrorCode::INVALID_ARGUMENT,
                "sFA fault '" + spec + "' must read NAME:CODE or NAME:CODE:TIMES");
  }
  const auto b = spec.find(':', a + 1);
  try {
    SfaFault f;
    f.code = std::stoi(spec.substr(a + 1, b == std::string::npos ? std::string::npos : b - a - 1));
    if (b != std::string::npos)
      f.times = std::stoi(spec.substr(b + 1));
    if (f.code <= 0 || f.times == 0)
      throw std::invalid_argument("range");
    sfa[spec.substr(0, a)] = f;
  } catch (const std::exception&) {
    throw Error(ErrorCode::INVALID_ARGUMENT, "sFA fault '" + spec +
                                                 "': CODE must be a positive number and TIMES a "
                                                 "non-zero number (negative: always)");
  }
}

EmulatedLms111::EmulatedLms111(LmsEmulatorConfig config, std::shared_ptr<ScanSource> source,
                               LmsFaults faults)
    : config_(std::move(config)), source_(std::move(source)), faults_(std::move(faults)) {
  if (!source_)
    throw Error(ErrorCode::INVALID_ARGUMENT, "the emulated LMS111 needs a scan source");
  const auto& s = config_.scan;
  if (!validPair(s.frequency, s.resolution) ||
      !validArea(s.start_angle, s.stop_angle, s.resolution))
    throw Error(ErrorCode::INVALID_ARGUMENT,
                "the emulator's power-up scan configuration is not one "
                "the LMS111 supports");
  powerUp(0.0);
}

void EmulatedLms111::powerUp(double now_s) {
  active_ = pending_ = config_.scan;
  output_ = DataOutputConfig{};
  measuring_ = true;
  power_up_s_ = now_s;
  ready_at_s_ = now_s + config_.spin_up_seconds;
  telegram_counter_ = scan_counter_ = 0;
}

std::uint32_t EmulatedLms111::clockUs(double now_s) const {
  const double us = (now_s - power_up_s_) * 1e6 * (1.0 + 1e-6 * config_.clock_drift_ppm);
  return static_cast<std::uint32_t>(config_.clock_start_us +
                                    static_cast<std::uint64_t>(std::max(0.0, us)));
}

int EmulatedLms111::state(double now_s) const {
  if (!measuring_)
    return 3;                                                    // idle
  return now_s < ready_at_s_ ? 5 : STATE_READY_FOR_MEASUREMENT;  // in preparation / ready
}

std::string EmulatedLms111::reply(const LmsSession& session, const std::string& type,
                                  const std::string& name,
                                  const std::function<void(FieldWriter&)>& fields) const {
  const auto w = makeWriter(session.protocol);
  w->word(type);
  w->word(name);
  if (fields)
    fields(*w);
  std::string payload = w->payload();
  // A real device ends a CoLa-B reply's command words with a space even when no field follows
  // (`sWA LMDscandatacfg `, `sWA EIHstCola ` in the recorded session).
  if (session.protocol == Protocol::COLA_B && payload.size() == type.size() + 1 + name.size())
    payload += ' ';
  return payload;
}

std::string EmulatedLms111::sfa(const LmsSession& session, int code) const {
  return sfaReply(session.protocol, code);
}

std::vector<std::string> EmulatedLms111::handle(const std::string& payload, LmsSession& session,
                                                double now_s) {
  const auto reader = makeReader(session.protocol, payload);
  std::string type, name;
  try {
    type = reader->word("command type");
    name = reader->word("command");
  } catch (const Error&) {
    return {sfa(session, SFA_UNKNOWN_COMMAND)};
  }
  std::vector<std::string> out;
  if (auto event = nextEvent(session.protocol))
    out.push_back(*event);
  out.push_back(answer(payload, type, name, *reader, session, now_s));
  return out;
}

std::optional<std::string> EmulatedLms111::nextEvent(Protocol protocol) {
  if (!recording_ || recording_->events.empty() || protocol != Protocol::COLA_B)
    return std::nullopt;
  return recording_->events[next_event_++ % recording_->events.size()];
}

std::string EmulatedLms111::answer(const std::string& payload, const std::string& type,
                                   const std::string& name, FieldReader& reader,
                                   LmsSession& session, double now_s) {
  const bool recorded = recording_ && session.protocol == Protocol::COLA_B;
  if (recorded) {
    const auto size = recording_->request_bytes.find(type + " " + name);
    if (size != recording_->request_bytes.end() && size->second != payload.size())
      return sfa(session,
                 payload.size() > size->second ? SFA_BUFFER_OVERFLOW : SFA_BUFFER_UNDERFLOW);
  }
  auto fault = faults_.sfa.find(name);
  if (fault != faults_.sfa.end() && fault->second.times != 0) {
    if (fault->second.times > 0)
      --fault->second.times;
    return sfa(session, fault->second.code);
  }
  try {
    std::string reply = dispatch(type, name, reader, session, now_s);
    if (recorded) {
      const auto it = recording_->reply_to.find(payload);
      if (it != recording_->reply_to.end())
        reply = it->second;
    }
    return reply;
  } catch (const SfaReply& e) {
    return sfa(session, e.code);
  } catch (const Error&) {
    return sfa(session, SFA_BUFFER_UNDERFLOW);  // too few or unreadable parameters
  }
}

// Long by design: one case per command of the device (docs/protocols.md), each a few lines of
// argument checks and state, in one place as in the vendor's telegram listing.
std::string EmulatedLms111::dispatch(const std::string& type, const std::string& name,
                                     FieldReader& r, LmsSession& session, double now_s) {
  auto requireLevel = [&]() {
    if (session.access_level < AUTHORISED_CLIENT_LEVEL)
      throw SfaReply{SFA_ACCESS_DENIED};
  };
  if (type == "sMN") {
    if (name == "SetAccessMode") {
      const auto level = static_cast<int>(r.unsignedValue("user level", 8));
      const auto password = static_cast<std::uint32_t>(r.unsignedValue("password"));
      expectEnd(r);
      const bool ok = level == AUTHORISED_CLIENT_LEVEL && password == AUTHORISED_CLIENT_PASSWORD;
      if (ok)
        session.access_level = level;
      return reply(session, "sAN", name, [&](FieldWriter& w) { w.unsignedValue(ok ? 1 : 0, 8); });
    }
    if (name == "mLMPsetscancfg") {
      requireLevel();
      DeviceScanConfig c = pending_;
      c.frequency = static_cast<std::uint32_t>(r.unsignedValue("scan frequency"));
      const auto sectors = r.unsignedValue("number of sectors", 16);
      c.resolution = static_cast<std::uint32_t>(r.unsignedValue("angular resolution"));
      c.start_angle = r.signedValue("start angle");
      c.stop_angle = r.signedValue("stop angle");
      expectEnd(r);
      const bool freq_ok = c.frequency == 2500 || c.frequency == 5000;
      const bool res_ok = c.resolution == 2500 || c.resolution == 5000;
      int result = SCANCFG_OK;
      if (!freq_ok && !res_ok)
        result = SCANCFG_BAD_BOTH;
      else if (!freq_ok)
        result = SCANCFG_BAD_FREQUENCY;
      else if (!res_ok || !validPair(c.frequency, c.resolution))
        result = SCANCFG_BAD_RESOLUTION;
      else if (sectors != 1 || !validArea(c.start_angle, c.stop_angle, c.resolution))
        result = SCANCFG_BAD_AREA;
      if (result == SCANCFG_OK)
        pending_ = c;
      return reply(session, "sAN", name, [&](FieldWriter& w) {
        w.unsignedValue(static_cast<std::uint64_t>(result), 8);
        w.unsignedValue(pending_.frequency);
        w.unsignedValue(1, 16);
        writeScanArea(w, pending_);
      });
    }
    if (name == "LMCstartmeas" || name == "LMCstopmeas") {
      expectEnd(r);
      requireLevel();
      const bool was_measuring = measuring_;
      measuring_ = name == "LMCstartmeas";
      if (measuring_ && !was_measuring)
        ready_at_s_ = now_s + config_.spin_up_seconds;
      return reply(session, "sAN", name, [](FieldWriter& w) { w.unsignedValue(0, 8); });
    }
    if (name == "Run") {
      expectEnd(r);
      // Leaves the authorised level and applies the configuration: the device re-initialises.
      const bool changed =
          pending_.frequency != active_.frequency || pending_.resolution != active_.resolution ||
          pending_.start_angle != active_.start_angle || pending_.stop_angle != active_.stop_angle;
      active_ = pending_;
      session.access_level = 0;
      if (changed && measuring_)
        ready_at_s_ = now_s + config_.spin_up_seconds;
      return reply(session, "sAN", name, [](FieldWriter& w) { w.unsignedValue(1, 8); });
    }
    throw SfaReply{SFA_UNKNOWN_METHOD};
  }
  if (type == "sRN") {
    expectEnd(r);
    if (name == "STlms") {
      return reply(session, "sRA", name, [&](FieldWriter& w) {
        w.unsignedValue(static_cast<std::uint64_t>(state(now_s)), 16);
        w.unsignedValue(0, 8);  // temperature within range
        w.unsignedValue(8, 16);
        w.characters("00:00:00");
        w.unsignedValue(10, 16);
        w.characters("01.01.2026");
        for (int led = 0; led < 3; ++led)
          w.unsignedValue(0, 8);  // LED 1..3 off
      });
    }
    if (name == "LMPscancfg") {
      return reply(session, "sRA", name, [&](FieldWriter& w) {
        w.unsignedValue(active_.frequency);
        w.unsignedValue(1, 16);
        writeScanArea(w, active_);
      });
    }
    if (name == "LMPoutputRange") {
      return reply(session, "sRA", name, [&](FieldWriter& w) {
        w.unsignedValue(1, 16);
        writeScanArea(w, active_, config_.reported_angle_error);
      });
    }
    if (name == "DeviceIdent") {
      return reply(session, "sRA", name, [&](FieldWriter& w) {
        w.unsignedValue(config_.device_name.size(), 16);
        w.characters(config_.device_name);
        w.unsignedValue(config_.firmware_version.size(), 16);
        w.characters(config_.firmware_version);
      });
    }
    if (name == "LMDscandata") {
      if (state(now_s) != STATE_READY_FOR_MEASUREMENT)
        throw SfaReply{SFA_LOCAL_CONDITION};
      auto scan = nextScan(now_s);
      if (!scan)
        throw SfaReply{SFA_LOCAL_CONDITION};
      scan->command_type = "sRA";
      return encodeScanTelegram(*scan, session.protocol);
    }
    throw SfaReply{SFA_UNKNOWN_VARIABLE};
  }
  if (type == "sWN") {
    if (name == "LMPoutputRange") {
      requireLevel();
      DeviceScanConfig c = pending_;
      if (r.unsignedValue("status code", 16) != 1)
        throw SfaReply{SFA_INVALID_DATA};
      const auto resolution = static_cast<std::uint32_t>(r.unsignedValue("angular resolution"));
      c.start_angle = r.signedValue("start angle");
      c.stop_angle = r.signedValue("stop angle");
      expectEnd(r);
      if (resolution != c.resolution || !validArea(c.start_angle, c.stop_angle, c.resolution))
        throw SfaReply{SFA_INVALID_DATA};
      pending_ = c;
      return reply(session, "sWA", name);
    }
    if (name == "LMDscandatacfg") {
      requireLevel();
      const DataOutputConfig o = readDataOutputConfig(r);
      output_ = o;
      return reply(session, "sWA", name);
    }
    throw SfaReply{SFA_UNKNOWN_VARIABLE};
  }
  if (type == "sEN") {
    if (name == "LMDscandata") {
      const auto on = r.unsignedValue("on/off", 8);
      expectEnd(r);
      if (on > 1)
        throw SfaReply{SFA_INVALID_DATA};
      session.streaming = on == 1;
      return reply(session, "sEA", name, [&](FieldWriter& w) { w.unsignedValue(on, 8); });
    }
    throw SfaReply{SFA_UNKNOWN_VARIABLE};
  }
  throw SfaReply{SFA_UNKNOWN_COMMAND};
}

std::optional<ScanTelegram> EmulatedLms111::nextScan(double now_s) {
  if (state(now_s) != STATE_READY_FOR_MEASUREMENT)
    return std::nullopt;
  const std::uint64_t index = scans_++;
  ++scan_counter_;
  if (output_.output_interval > 1 && scan_counter_ % output_.output_interval != 0)
    return std::nullopt;
  ScanGeometry g;
  g.start_angle_deg = active_.start_angle / 10000.0;
  g.step_deg = active_.resolution / 10000.0;
  g.count = active_.count();
  g.scan_frequency_hz = active_.frequency / 100.0;
  ScanContent content = source_->scan(g, now_s - power_up_s_, index);
  content.distances_mm.resize(g.count, 0);
  content.rssi.resize(g.count, 0);

  ScanTelegram s;
  s.command_type = "sSN";
  s.version = 1;
  s.device_number = 1;
  s.serial_number = config_.serial_number;
  s.telegram_counter = ++telegram_counter_;
  s.scan_counter = scan_counter_;
  s.time_since_startup_us = clockUs(now_s);
  // Sent once the 270 deg of the scan are measured: 3/4 of a mirror turn after the first ray.
  s.time_of_transmission_us = clockUs(now_s + 0.75 * scanPeriod());
  s.scan_frequency = active_.frequency;
  // Rays per second over the full turn (360 deg / resolution x frequency), in 100 Hz units.
  s.measurement_frequency =
      static_cast<std::uint32_t>(std::lround(360.0 / g.step_deg * g.scan_frequency_hz / 100.0));
  ScanChannel dist;
  dist.name = "DIST1";
  dist.start_angle = active_.start_angle;
  dist.angular_step = static_cast<std::uint16_t>(active_.resolution);
  dist.values = std::move(content.distances_mm);
  s.channels16.push_back(std::move(dist));
  if (output_.rssi) {
    ScanChannel rssi = s.channels16.front();
    rssi.name = "RSSI1";
    rssi.values = std::move(content.rssi);
    if (!output_.rssi_16bit) {
      for (auto& v : rssi.values)
        v = std::min<std::uint16_t>(v, 0xFF);
    }
    (output_.rssi_16bit ? s.channels16 : s.channels8).push_back(std::move(rssi));
  }
  if (output_.device_name)
    s.device_name = config_.device_name;
  if (output_.comment)
    s.comment = "emulated";
  if (output_.time_stamp) {
    ScanTimestamp t;
    t.year = 2026;
    t.month = 1;
    t.day = 1;
    const double since = now_s - power_up_s_;
    const auto whole = static_cast<std::uint64_t>(since);
    t.hour = static_cast<std::uint8_t>((whole / 3600) % 24);
    t.minute = static_cast<std::uint8_t>((whole / 60) % 60);
    t.second = static_cast<std::uint8_t>(whole % 60);
    t.microsecond = static_cast<std::uint32_t>((since - whole) * 1e6);
    s.timestamp = t;
  }
  return s;
}

}  // namespace emulation
}  // namespace dormant_tree_modeling
