#include "dormant_tree_modeling/lms111/scan_telegram.h"

#include <cstdio>
#include <cstring>
#include <nlohmann/json.hpp>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/lms111/cola_fields.h"

namespace dormant_tree_modeling {
namespace lms111 {

namespace {

constexpr std::size_t MAX_CHANNELS = 16;
constexpr std::size_t MAX_VALUES = 10000;      // a channel of the LMS1xx holds at most 1081
constexpr std::size_t CHANNEL_NAME_WIDTH = 5;  // DIST1, RSSI1, ...: fixed width in CoLa-B
constexpr std::size_t EVENT_TYPE_WIDTH = 4;

bool readFlag(FieldReader& r, const char* field) {
  const auto v = r.unsignedValue(field, 16);
  if (v > 1) {
    throw Error(ErrorCode::PARSE_ERROR, std::string("telegram field '") + field +
                                            "': flag must be 0 or 1, is " + std::to_string(v));
  }
  return v == 1;
}

std::vector<ScanChannel> readChannels(FieldReader& r, bool sixteen_bit) {
  const auto count =
      r.unsignedValue(sixteen_bit ? "number of 16-bit channels" : "number of 8-bit channels", 16);
  if (count > MAX_CHANNELS) {
    throw Error(ErrorCode::PARSE_ERROR, "telegram claims " + std::to_string(count) +
                                            " channels (at most " + std::to_string(MAX_CHANNELS) +
                                            " are plausible)");
  }
  std::vector<ScanChannel> channels(count);
  for (auto& c : channels) {
    c.name = r.label("channel name", CHANNEL_NAME_WIDTH);
    c.scale = r.floatValue("scale factor");
    c.offset = r.floatValue("scale offset");
    c.start_angle = r.signedValue("start angle");
    c.angular_step = static_cast<std::uint16_t>(r.unsignedValue("angular step", 16));
    const auto n = r.unsignedValue("number of values", 16);
    if (n > MAX_VALUES) {
      throw Error(ErrorCode::PARSE_ERROR, "channel " + c.name + " claims " + std::to_string(n) +
                                              " values (at most " + std::to_string(MAX_VALUES) +
                                              ")");
    }
    c.values.reserve(n);
    for (std::uint64_t i = 0; i < n; ++i) {
      try {
        c.values.push_back(
            static_cast<std::uint16_t>(r.unsignedValue("channel value", sixteen_bit ? 16 : 8)));
      } catch (const Error& e) {
        throw Error(ErrorCode::PARSE_ERROR, "channel " + c.name + ", value " + std::to_string(i) +
                                                " of " + std::to_string(n) + ": " + e.what());
      }
    }
  }
  return channels;
}

std::string hex(std::uint64_t v) {
  char buf[24];
  std::snprintf(buf, sizeof buf, "%llX", static_cast<unsigned long long>(v));
  return buf;
}

}  // namespace

const ScanChannel* ScanTelegram::channel(const std::string& name) const {
  for (const auto* list : {&channels16, &channels8}) {
    for (const auto& c : *list) {
      if (c.name == name)
        return &c;
    }
  }
  return nullptr;
}

bool isScanTelegram(const std::string& payload) {
  static const std::string NAME = "LMDscandata";
  constexpr std::size_t TYPE_AND_SPACE = 4;  // "sSN " or "sRA "
  const bool typed = payload.compare(0, TYPE_AND_SPACE, "sSN ") == 0 ||
                     payload.compare(0, TYPE_AND_SPACE, "sRA ") == 0;
  const std::size_t end = TYPE_AND_SPACE + NAME.size();
  return typed && payload.compare(TYPE_AND_SPACE, NAME.size(), NAME) == 0 &&
         (payload.size() == end || payload[end] == ' ');
}

// One walk over the telegram's fields in their order on the wire (docs/protocols.md), with the
// field and offset in every error; split, the order would be harder to check against SICK's
// listing.
ScanTelegram parseScanTelegram(const std::string& payload, Protocol protocol) {
  const auto reader = makeReader(protocol, payload);
  FieldReader& r = *reader;
  ScanTelegram s;
  s.command_type = r.word("command type");
  if (s.command_type != "sSN" && s.command_type != "sRA") {
    throw Error(ErrorCode::PARSE_ERROR,
                "not a scan telegram: command type '" + s.command_type + "' (sSN or sRA)");
  }
  const std::string name = r.word("command");
  if (name != "LMDscandata")
    throw Error(ErrorCode::PARSE_ERROR, "not a scan telegram: command '" + name + "'");
  s.version = static_cast<std::uint16_t>(r.unsignedValue("version", 16));
  s.device_number = static_cast<std::uint16_t>(r.unsignedValue("device number", 16));
  s.serial_number = static_cast<std::uint32_t>(r.unsignedValue("serial number"));
  s.status_code = static_cast<std::uint8_t>(r.unsignedValue("device status", 8));
  s.device_status = static_cast<std::uint8_t>(r.unsignedValue("device status", 8));
  s.telegram_counter = static_cast<std::uint16_t>(r.unsignedValue("telegram counter", 16));
  s.scan_counter = static_cast<std::uint16_t>(r.unsignedValue("scan counter", 16));
  s.time_since_startup_us = static_cast<std::uint32_t>(r.unsignedValue("time since start-up"));
  s.time_of_transmission_us = static_cast<std::uint32_t>(r.unsignedValue("time of transmission"));
  for (auto& v : s.digital_inputs)
    v = static_cast<std::uint16_t>(r.unsignedValue("digital inputs", 8));
  for (auto& v : s.digital_outputs)
    v = static_cast<std::uint16_t>(r.unsignedValue("digital outputs", 8));
  s.reserved = static_cast<std::uint16_t>(r.unsignedValue("reserved", 16));
  s.scan_frequency = static_cast<std::uint32_t>(r.unsignedValue("scan frequency"));
  s.measurement_frequency = static_cast<std::uint32_t>(r.unsignedValue("measurement frequency"));
  const auto encoders = r.unsignedValue("number of encoders", 16);
  if (encoders > MAX_CHANNELS)
    throw Error(ErrorCode::PARSE_ERROR,
                "telegram claims " + std::to_string(encoders) + " encoders");
  for (std::uint64_t i = 0; i < encoders; ++i) {
    ScanEncoder e;
    e.position = static_cast<std::uint32_t>(r.unsignedValue("encoder position"));
    e.speed = static_cast<std::uint16_t>(r.unsignedValue("encoder speed", 16));
    s.encoders.push_back(e);
  }
  s.channels16 = readChannels(r, true);
  s.channels8 = readChannels(r, false);
  if (readFlag(r, "position flag")) {
    ScanPosition p;
    p.x = r.floatValue("position x");
    p.y = r.floatValue("position y");
    p.z = r.floatValue("position z");
    p.rot_x = r.floatValue("rotation x");
    p.rot_y = r.floatValue("rotation y");
    p.rot_z = r.floatValue("rotation z");
    p.rotation_type = static_cast<std::uint8_t>(r.unsignedValue("rotation type", 8));
    s.position = p;
  }
  if (readFlag(r, "device name flag")) {
    const auto n = r.unsignedValue("device name length", 16);
    s.device_name = r.characters("device name", n);
  }
  if (readFlag(r, "comment flag")) {
    const auto n = r.unsignedValue("comment length", 16);
    s.comment = r.characters("comment", n);
  }
  if (readFlag(r, "time stamp flag")) {
    ScanTimestamp t;
    t.year = static_cast<std::uint16_t>(r.unsignedValue("year", 16));
    t.month = static_cast<std::uint8_t>(r.unsignedValue("month", 8));
    t.day = static_cast<std::uint8_t>(r.unsignedValue("day", 8));
    t.hour = static_cast<std::uint8_t>(r.unsignedValue("hour", 8));
    t.minute = static_cast<std::uint8_t>(r.unsignedValue("minute", 8));
    t.second = static_cast<std::uint8_t>(r.unsignedValue("second", 8));
    t.microsecond = static_cast<std::uint32_t>(r.unsignedValue("microsecond"));
    s.timestamp = t;
  }
  if (readFlag(r, "event flag")) {
    ScanEvent e;
    e.type = r.label("event type", EVENT_TYPE_WIDTH);
    e.encoder_position = static_cast<std::uint32_t>(r.unsignedValue("event encoder position"));
    e.time_us = static_cast<std::uint32_t>(r.unsignedValue("event time"));
    e.angle = r.signedValue("event angle");
    s.event = e;
  }
  if (!r.atEnd()) {
    throw Error(ErrorCode::PARSE_ERROR,
                "telegram has unexpected text after the last block, at "
                "character " +
                    std::to_string(r.position()));
  }
  return s;
}

std::string encodeScanTelegram(const ScanTelegram& s, Protocol protocol) {
  const auto writer = makeWriter(protocol);
  FieldWriter& w = *writer;
  w.word(s.command_type.empty() ? std::string("sSN") : s.command_type);
  w.word("LMDscandata");
  w.unsignedValue(s.version, 16);
  w.unsignedValue(s.device_number, 16);
  w.unsignedValue(s.serial_number);
  w.unsignedValue(s.status_code, 8);
  w.unsignedValue(s.device_status, 8);
  w.unsignedValue(s.telegram_counter, 16);
  w.unsignedValue(s.scan_counter, 16);
  w.unsignedValue(s.time_since_startup_us);
  w.unsignedValue(s.time_of_transmission_us);
  for (const auto v : s.digital_inputs)
    w.unsignedValue(v, 8);
  for (const auto v : s.digital_outputs)
    w.unsignedValue(v, 8);
  w.unsignedValue(s.reserved, 16);
  w.unsignedValue(s.scan_frequency);
  w.unsignedValue(s.measurement_frequency);
  w.unsignedValue(s.encoders.size(), 16);
  for (const auto& e : s.encoders) {
    w.unsignedValue(e.position);
    w.unsignedValue(e.speed, 16);
  }
  for (const auto* channels : {&s.channels16, &s.channels8}) {
    const int bits = channels == &s.channels16 ? 16 : 8;
    w.unsignedValue(channels->size(), 16);
    for (const auto& c : *channels) {
      w.label(c.name, CHANNEL_NAME_WIDTH);
      w.floatValue(c.scale);
      w.floatValue(c.offset);
      w.signedValue(c.start_angle);
      w.unsignedValue(c.angular_step, 16);
      w.unsignedValue(c.values.size(), 16);
      for (const auto v : c.values)
        w.unsignedValue(v, bits);
    }
  }
  w.unsignedValue(s.position ? 1 : 0, 16);
  if (s.position) {
    for (const float f : {s.position->x, s.position->y, s.position->z, s.position->rot_x,
                          s.position->rot_y, s.position->rot_z})
      w.floatValue(f);
    w.unsignedValue(s.position->rotation_type, 8);
  }
  for (const auto* text : {&s.device_name, &s.comment}) {
    w.unsignedValue(*text ? 1 : 0, 16);
    if (*text) {
      w.unsignedValue((*text)->size(), 16);
      w.characters(**text);
    }
  }
  w.unsignedValue(s.timestamp ? 1 : 0, 16);
  if (s.timestamp) {
    const auto& t = *s.timestamp;
    w.unsignedValue(t.year, 16);
    for (const std::uint64_t v : {t.month, t.day, t.hour, t.minute, t.second})
      w.unsignedValue(v, 8);
    w.unsignedValue(t.microsecond);
  }
  w.unsignedValue(s.event ? 1 : 0, 16);
  if (s.event) {
    w.label(s.event->type, EVENT_TYPE_WIDTH);
    w.unsignedValue(s.event->encoder_position);
    w.unsignedValue(s.event->time_us);
    w.signedValue(s.event->angle);
  }
  return w.payload();
}

std::string scanTelegramToJson(const ScanTelegram& s) {
  auto channels = [](const std::vector<ScanChannel>& list) {
    nlohmann::json a = nlohmann::json::array();
    for (const auto& c : list) {
      a.push_back({{"name", c.name},
                   {"scale", c.scale},
                   {"offset", c.offset},
                   {"start_angle_deg", c.startAngleDeg()},
                   {"angular_step_deg", c.stepDeg()},
                   {"count", c.values.size()},
                   {"values", c.values}});
    }
    return a;
  };
  nlohmann::json j{{"command_type", s.command_type},
                   {"version", s.version},
                   {"device_number", s.device_number},
                   {"serial_number", hex(s.serial_number)},
                   {"device_status", {s.status_code, s.device_status}},
                   {"telegram_counter", s.telegram_counter},
                   {"scan_counter", s.scan_counter},
                   {"time_since_startup_us", s.time_since_startup_us},
                   {"time_of_transmission_us", s.time_of_transmission_us},
                   {"digital_inputs", {s.digital_inputs[0], s.digital_inputs[1]}},
                   {"digital_outputs", {s.digital_outputs[0], s.digital_outputs[1]}},
                   {"scan_frequency_hz", s.scanFrequencyHz()},
                   {"measurement_frequency_hz", 100.0 * s.measurement_frequency},
                   {"encoders", nlohmann::json::array()},
                   {"channels_16bit", channels(s.channels16)},
                   {"channels_8bit", channels(s.channels8)}};
  for (const auto& e : s.encoders)
    j["encoders"].push_back({{"position", e.position}, {"speed", e.speed}});
  if (s.position) {
    const auto& p = *s.position;
    j["position"] = {{"x", p.x},
                     {"y", p.y},
                     {"z", p.z},
                     {"rot_x", p.rot_x},
                     {"rot_y", p.rot_y},
                     {"rot_z", p.rot_z},
                     {"rotation_type", p.rotation_type}};
  }
  if (s.device_name)
    j["device_name"] = *s.device_name;
  if (s.comment)
    j["comment"] = *s.comment;
  if (s.timestamp) {
    const auto& t = *s.timestamp;
    j["timestamp"] = {{"year", t.year},
                      {"month", t.month},
                      {"day", t.day},
                      {"hour", t.hour},
                      {"minute", t.minute},
                      {"second", t.second},
                      {"microsecond", t.microsecond}};
  }
  if (s.event) {
    j["event"] = {{"type", s.event->type},
                  {"encoder_position", s.event->encoder_position},
                  {"time_us", s.event->time_us},
                  {"angle_deg", s.event->angle / 10000.0}};
  }
  // Names come from the device: invalid UTF-8 is replaced, not a reason to throw.
  return j.dump(1, ' ', false, nlohmann::json::error_handler_t::replace) + "\n";
}

}  // namespace lms111
}  // namespace dormant_tree_modeling
