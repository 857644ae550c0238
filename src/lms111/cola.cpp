#include "dormant_tree_modeling/lms111/cola.h"

#include <cstdio>
#include <cstring>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace lms111 {

namespace {

bool isHexDigit(char c) {
  return (c >= '0' && c <= '9') || (c >= 'A' && c <= 'F') || (c >= 'a' && c <= 'f');
}

}  // namespace

const char* protocolName(Protocol protocol) {
  return protocol == Protocol::COLA_A ? "CoLa-A" : "CoLa-B";
}

std::string frame(Protocol protocol, const std::string& payload) {
  return protocol == Protocol::COLA_A ? frameColaA(payload) : frameColaB(payload);
}

std::unique_ptr<Framer> makeFramer(Protocol protocol, std::size_t max_payload) {
  if (protocol == Protocol::COLA_A)
    return std::make_unique<ColaAFramer>(max_payload);
  return std::make_unique<ColaBFramer>(max_payload);
}

std::string frameColaA(const std::string& text) {
  return std::string(1, STX) + text + std::string(1, ETX);
}

const std::string COLA_B_MAGIC(4, '\x02');

char colaBChecksum(const char* payload, std::size_t size) {
  char sum = 0;
  for (std::size_t i = 0; i < size; ++i)
    sum = static_cast<char>(sum ^ payload[i]);
  return sum;
}

std::uint32_t colaBDeclaredLength(const char* frame) {
  std::uint32_t length = 0;
  for (std::size_t i = COLA_B_MAGIC.size(); i < COLA_B_HEADER_BYTES; ++i)
    length = (length << 8) | static_cast<unsigned char>(frame[i]);
  return length;
}

std::string frameColaB(const std::string& payload) {
  std::string out = COLA_B_MAGIC;
  const auto n = static_cast<std::uint32_t>(payload.size());
  for (int shift = 24; shift >= 0; shift -= 8)
    out.push_back(static_cast<char>((n >> shift) & 0xFF));
  out += payload;
  out.push_back(colaBChecksum(payload.data(), payload.size()));
  return out;
}

// Both framers consume their buffer through a read position and compact it only when the
// consumed part is at least half of it, so that resynchronising byte by byte (a flood of STX
// or of magic bytes) stays linear in the input.
namespace {

void compact(std::string& buffer, std::size_t& pos) {
  if (pos > 0 && pos * 2 >= buffer.size()) {
    buffer.erase(0, pos);
    pos = 0;
  }
}

}  // namespace

void ColaAFramer::feed(const char* data, std::size_t size) {
  buffer_.append(data, size);
}

std::optional<std::string> ColaAFramer::next() {
  for (;;) {
    const std::size_t start = buffer_.find(STX, pos_);
    if (start == std::string::npos) {
      skipped_ += buffer_.size() - pos_;
      buffer_.clear();
      pos_ = 0;
      return std::nullopt;
    }
    skipped_ += start - pos_;
    pos_ = start;
    // A second STX before the ETX means the first telegram was cut short: restart there.
    const std::size_t end = buffer_.find_first_of(std::string{STX, ETX}, pos_ + 1);
    if (end == std::string::npos) {
      if (buffer_.size() - pos_ > max_telegram_) {
        ++dropped_;
        buffer_.clear();
        pos_ = 0;
      }
      compact(buffer_, pos_);
      return std::nullopt;
    }
    if (buffer_[end] == STX || end - pos_ - 1 > max_telegram_) {
      ++dropped_;
      pos_ = buffer_[end] == STX ? end : end + 1;
      compact(buffer_, pos_);
      continue;
    }
    std::string telegram = buffer_.substr(pos_ + 1, end - pos_ - 1);
    pos_ = end + 1;
    compact(buffer_, pos_);
    return telegram;
  }
}

void ColaBFramer::feed(const char* data, std::size_t size) {
  buffer_.append(data, size);
}

std::optional<std::string> ColaBFramer::next() {
  for (;;) {
    const std::size_t start = buffer_.find(COLA_B_MAGIC, pos_);
    if (start == std::string::npos) {
      // Keep a possible beginning of the magic at the end.
      std::size_t keep = 0;
      while (keep < 3 && keep < buffer_.size() - pos_ &&
             buffer_[buffer_.size() - 1 - keep] == COLA_B_MAGIC[0])
        ++keep;
      skipped_ += buffer_.size() - pos_ - keep;
      buffer_.erase(0, buffer_.size() - keep);
      pos_ = 0;
      return std::nullopt;
    }
    skipped_ += start - pos_;
    pos_ = start;
    if (buffer_.size() - pos_ < COLA_B_HEADER_BYTES) {
      compact(buffer_, pos_);
      return std::nullopt;
    }
    const std::uint32_t length = colaBDeclaredLength(buffer_.data() + pos_);
    if (length > max_payload_) {
      ++dropped_;
      ++pos_;  // resynchronise on the next magic
      continue;
    }
    const std::size_t frame_bytes = COLA_B_HEADER_BYTES + static_cast<std::size_t>(length) + 1;
    if (buffer_.size() - pos_ < frame_bytes) {
      compact(buffer_, pos_);
      return std::nullopt;
    }
    const char* payload = buffer_.data() + pos_ + COLA_B_HEADER_BYTES;
    if (colaBChecksum(payload, length) != payload[length]) {
      ++bad_checksum_;
      ++pos_;
      continue;
    }
    std::string out(payload, length);
    pos_ += frame_bytes;
    compact(buffer_, pos_);
    return out;
  }
}

std::optional<std::int64_t> parseColaNumber(const std::string& t) {
  if (t.empty() || t.size() > 17)
    return std::nullopt;
  if (t[0] == '+' || t[0] == '-') {
    if (t.size() == 1)
      return std::nullopt;
    std::int64_t v = 0;
    for (std::size_t i = 1; i < t.size(); ++i) {
      if (t[i] < '0' || t[i] > '9')
        return std::nullopt;
      v = v * 10 + (t[i] - '0');
    }
    return t[0] == '-' ? -v : v;
  }
  if (t.size() > 16)
    return std::nullopt;
  std::uint64_t v = 0;
  for (const char c : t) {
    if (!isHexDigit(c))
      return std::nullopt;
    v = (v << 4) | static_cast<std::uint64_t>(c <= '9' ? c - '0' : (c | 0x20) - 'a' + 10);
  }
  return static_cast<std::int64_t>(v);
}

std::string describeSfaError(int code) {
  switch (code) {
    case SFA_ACCESS_DENIED:
      return "access denied (log in with SetAccessMode first)";
    case SFA_UNKNOWN_METHOD:
      return "unknown method";
    case SFA_UNKNOWN_VARIABLE:
      return "unknown variable";
    case SFA_LOCAL_CONDITION:
      return "local condition failed (the device is not in a state that allows this)";
    case SFA_INVALID_DATA:
      return "invalid data";
    case SFA_UNKNOWN_ERROR:
      return "unknown error";
    case SFA_BUFFER_OVERFLOW:
      return "buffer overflow (more parameters than the telegram's layout holds)";
    case SFA_BUFFER_UNDERFLOW:
      return "buffer underflow (too few parameters)";
    case SFA_UNKNOWN_TYPE:
      return "unknown type";
    case SFA_WRITE_ACCESS_DENIED:
      return "write access denied";
    case SFA_UNKNOWN_NAMESERVER_COMMAND:
      return "unknown command";
    case SFA_UNKNOWN_COLA_COMMAND:
      return "unknown CoLa command";
    case SFA_SERVER_BUSY:
      return "server busy";
    case SFA_FLEX_OUT_OF_BOUNDS:
      return "flexible array out of bounds";
    case SFA_UNKNOWN_EVENT:
      return "unknown event";
    case SFA_COLA_A_VALUE_OVERFLOW:
      return "CoLa-A value overflow (a value wider than its field)";
    case SFA_COLA_A_INVALID_CHARACTER:
      return "CoLa-A invalid character";
    default:
      return "unknown error code " + std::to_string(code);
  }
}

std::optional<int> sfaCode(Protocol protocol, const std::string& payload) {
  if (payload.compare(0, 3, "sFA") != 0)
    return std::nullopt;
  std::size_t pos = 3;
  if (protocol == Protocol::COLA_A) {
    if (payload.size() < 5 || payload[3] != ' ')
      return std::nullopt;
    const auto code = parseColaNumber(payload.substr(4));
    if (!code || *code < 0 || *code > 0xFFFF)
      return std::nullopt;
    return static_cast<int>(*code);
  }
  if (payload.size() == 6 && payload[3] == ' ')
    pos = 4;
  if (payload.size() - pos == 2) {
    return (static_cast<unsigned char>(payload[pos]) << 8) |
           static_cast<unsigned char>(payload[pos + 1]);
  }
  if (payload.size() - pos == 1)
    return static_cast<unsigned char>(payload[pos]);
  return std::nullopt;
}

std::string sfaReply(Protocol protocol, int code) {
  if (protocol == Protocol::COLA_A) {
    char buf[16];
    std::snprintf(buf, sizeof buf, "sFA %X", static_cast<unsigned>(code) & 0xFFFF);
    return buf;
  }
  return std::string("sFA") + static_cast<char>((code >> 8) & 0xFF) +
         static_cast<char>(code & 0xFF);
}

std::string replyTypeOf(const std::string& type) {
  if (type == "sRN")
    return "sRA";
  if (type == "sWN")
    return "sWA";
  if (type == "sMN")
    return "sAN";
  if (type == "sEN")
    return "sEA";
  return type;
}

std::string deviceStateName(int state) {
  static const char* NAMES[] = {
      "undefined", "initialisation", "configuration", "idle",
      "rotated",   "in preparation", "ready",         "ready for measurement"};
  if (state >= 0 && state <= 7)
    return NAMES[state];
  return "unknown state " + std::to_string(state);
}

}  // namespace lms111
}  // namespace dormant_tree_modeling
