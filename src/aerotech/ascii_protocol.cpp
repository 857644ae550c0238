#include "dormant_tree_modeling/aerotech/ascii_protocol.h"

#include <cstdio>
#include <cstdlib>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/printable.h"

namespace dormant_tree_modeling {
namespace aerotech {

namespace {

// Positions and velocities go out with enough digits for 0.1 µm / 0.0001 deg.
std::string number(double v) {
  char buf[32];
  std::snprintf(buf, sizeof buf, "%.6f", v);
  return buf;
}

template <std::size_t N>
std::string namedBits(std::uint32_t bits, const std::pair<int, const char*> (&names)[N]) {
  std::string out;
  std::uint32_t named = 0;
  for (const auto& [bit, name] : names) {
    named |= 1u << bit;
    if (bits & (1u << bit))
      out += (out.empty() ? "" : ", ") + std::string(name);
  }
  for (int bit = 0; bit < 32; ++bit) {
    if ((bits & (1u << bit)) && !(named & (1u << bit)))
      out += (out.empty() ? "" : ", ") + std::string("bit ") + std::to_string(bit);
  }
  return out;
}

}  // namespace

double Reply::number() const {
  const char* begin = value.c_str();
  char* end = nullptr;
  const double v = std::strtod(begin, &end);
  if (value.empty() || end != begin + value.size())
    throw Error(ErrorCode::PARSE_ERROR,
                "reply value '" + printableBytes(value, 40) + "' is not a number");
  return v;
}

Reply parseReply(const std::string& line) {
  if (line.empty())
    throw Error(ErrorCode::PARSE_ERROR, "empty reply line");
  Reply r;
  switch (line[0]) {
    case '%':
    case '!':
    case '#':
    case '$':
      r.status = static_cast<ReplyStatus>(line[0]);
      break;
    default:
      throw Error(ErrorCode::PARSE_ERROR,
                  "reply '" + printableBytes(line, 80) + "' does not start with % ! # or $");
  }
  r.value = line.substr(1);
  return r;
}

const char* replyStatusName(ReplyStatus status) {
  switch (status) {
    case ReplyStatus::SUCCESS:
      return "success";
    case ReplyStatus::INVALID:
      return "invalid command";
    case ReplyStatus::FAULT:
      return "axis fault";
    case ReplyStatus::TIMEOUT:
      return "controller timeout";
  }
  return "?";
}

std::string AxisStatus::describe() const {
  static const std::pair<int, const char*> NAMES[] = {
      {0, "enabled"}, {1, "homed"},           {2, "in position"},     {3, "move active"},
      {14, "homing"}, {22, "positive limit"}, {23, "negative limit"}, {31, "emergency stop"}};
  const std::string s = namedBits(bits, NAMES);
  return s.empty() ? "disabled, not homed" : s;
}

std::string describeFaults(std::uint32_t bits) {
  static const std::pair<int, const char*> NAMES[] = {
      {0, "position error"},      {1, "over-current"},        {2, "positive hard limit"},
      {3, "negative hard limit"}, {4, "positive soft limit"}, {5, "negative soft limit"},
      {6, "amplifier fault"},     {7, "feedback fault"},      {11, "emergency stop"},
      {19, "encoder fault"},      {20, "communication fault"}};
  const std::string s = namedBits(bits, NAMES);
  return s.empty() ? "none" : s;
}

namespace command {
std::string enable(const std::string& axis) {
  return "ENABLE " + axis;
}
std::string disable(const std::string& axis) {
  return "DISABLE " + axis;
}
std::string home(const std::string& axis) {
  return "HOME " + axis;
}
std::string waitModeNoWait() {
  return "WAIT MODE NOWAIT";
}
std::string moveAbsolute(const std::string& axis, double position, double velocity) {
  return "MOVEABS " + axis + " " + number(position) + " " + axis + "F" + number(velocity);
}
std::string moveIncremental(const std::string& axis, double distance, double velocity) {
  return "MOVEINC " + axis + " " + number(distance) + " " + axis + "F" + number(velocity);
}
std::string freerun(const std::string& axis, double velocity) {
  return "FREERUN " + axis + " " + number(velocity);
}
std::string abort(const std::string& axis) {
  return "ABORT " + axis;
}
std::string faultAck(const std::string& axis) {
  return "FAULTACK " + axis;
}
std::string acknowledgeAll() {
  return "ACKNOWLEDGEALL";
}
std::string positionFeedback(const std::string& axis) {
  return "PFBKPROG(" + axis + ")";
}
std::string planeStatus(int plane) {
  return "PLANESTATUS(" + std::to_string(plane) + ")";
}
std::string velocityFeedback(const std::string& axis) {
  return "VFBK(" + axis + ")";
}
std::string axisStatus(const std::string& axis) {
  return "AXISSTATUS(" + axis + ")";
}
std::string axisFault(const std::string& axis) {
  return "AXISFAULT(" + axis + ")";
}
}  // namespace command

void LineFramer::feed(const char* data, std::size_t size) {
  for (std::size_t i = 0; i < size; ++i) {
    const char c = data[i];
    if (discarding_) {
      if (c == '\n')
        discarding_ = false;
      continue;
    }
    buffer_.push_back(c);
    if (c != '\n' && buffer_.size() > max_line_) {
      // Keep the complete lines before the overlong one, drop the rest of it.
      const std::size_t start = buffer_.rfind('\n');
      buffer_.erase(start == std::string::npos ? 0 : start + 1);
      discarding_ = true;
      ++dropped_;
    }
  }
}

std::optional<std::string> LineFramer::next() {
  const std::size_t end = buffer_.find('\n');
  if (end == std::string::npos)
    return std::nullopt;
  std::string line = buffer_.substr(0, end);
  buffer_.erase(0, end + 1);
  if (!line.empty() && line.back() == '\r')
    line.pop_back();
  return line;
}

}  // namespace aerotech
}  // namespace dormant_tree_modeling
