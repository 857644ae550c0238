#include "dormant_tree_modeling/lms111/cola.h"

#include <cstring>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace lms111 {

namespace {

const char COLA_B_MAGIC[4] = {0x02, 0x02, 0x02, 0x02};

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

std::string frameColaB(const std::string& payload) {
  std::string out(COLA_B_MAGIC, 4);
  const auto n = static_cast<std::uint32_t>(payload.size());
  for (int shift = 24; shift >= 0; shift -= 8)
    out.push_back(static_cast<char>((n >> shift) & 0xFF));
  out += payload;
  char sum = 0;
  for (const char c : payload)
    sum = static_cast<char>(sum ^ c);
  out.push_back(sum);
  return out;
}

void ColaAFramer::feed(const char* data, std::size_t size) {
  buffer_.append(data, size);
}

std::optional<std::string> ColaAFramer::next() {
  for (;;) {
    const std::size_t start = buffer_.find(STX);
    if (start == std::string::npos) {
      skipped_ += buffer_.size();
      buffer_.clear();
      return std::nullopt;
    }
    if (start > 0) {
      skipped_ += start;
      buffer_.erase(0, start);
    }
    // A second STX before the ETX means the first telegram was cut short: restart there.
    const std::size_t end = buffer_.find_first_of(std::string{STX, ETX}, 1);
    if (end == std::string::npos) {
      if (buffer_.size() > max_telegram_) {
        ++dropped_;
        buffer_.clear();
      }
      return std::nullopt;
    }
    if (buffer_[end] == STX) {
      ++dropped_;
      buffer_.erase(0, end);
      continue;
    }
    if (end - 1 > max_telegram_) {
      ++dropped_;
      buffer_.erase(0, end + 1);
      continue;
    }
    std::string telegram = buffer_.substr(1, end - 1);
    buffer_.erase(0, end + 1);
    return telegram;
  }
}

void ColaBFramer::feed(const char* data, std::size_t size) {
  buffer_.append(data, size);
}

std::optional<std::string> ColaBFramer::next() {
  for (;;) {
    const std::size_t start = buffer_.find(std::string(COLA_B_MAGIC, 4));
    if (start == std::string::npos) {
      // Keep a possible beginning of the magic at the end.
      std::size_t keep = 0;
      while (keep < 3 && keep < buffer_.size() &&
             buffer_[buffer_.size() - 1 - keep] == COLA_B_MAGIC[0])
        ++keep;
      skipped_ += buffer_.size() - keep;
      buffer_.erase(0, buffer_.size() - keep);
      return std::nullopt;
    }
    if (start > 0) {
      skipped_ += start;
      buffer_.erase(0, start);
    }
    if (buffer_.size() < 8)
      return std::nullopt;
    std::uint32_t length = 0;
    for (int i = 4; i < 8; ++i)
      length = (length << 8) | static_cast<unsigned char>(buffer_[i]);
    if (length > max_payload_) {
      ++dropped_;
      buffer_.erase(0, 1);  // resynchronise on the next magic
      continue;
    }
    if (buffer_.size() < 8 + static_cast<std::size_t>(length) + 1)
      return std::nullopt;
    std::string payload = buffer_.substr(8, length);
    char sum = 0;
    for (const char c : payload)
      sum = static_cast<char>(sum ^ c);
    if (sum != buffer_[8 + length]) {
      ++bad_checksum_;
      buffer_.erase(0, 1);
      continue;
    }
    buffer_.erase(0, 8 + static_cast<std::size_t>(length) + 1);
    return payload;
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
    case 1:
      return "access denied (log in with SetAccessMode first)";
    case 2:
      return "unknown method";
    case 3:
      return "unknown variable";
    case 4:
      return "local condition failed (the device is not in a state that allows this)";
    case 5:
      return "invalid data";
    case 8:
      return "buffer underflow (too few parameters)";
    case 10:
      return "write access denied";
    case 11:
      return "unknown command";
    default:
      return "unknown error code " + std::to_string(code);
  }
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
