#include "dormant_tree_modeling/lms111/capture.h"

#include <cctype>
#include <filesystem>
#include <fstream>
#include <iterator>
#include <sstream>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace lms111 {

namespace {

int hexValue(char c) {
  if (c >= '0' && c <= '9')
    return c - '0';
  if (c >= 'a' && c <= 'f')
    return c - 'a' + 10;
  if (c >= 'A' && c <= 'F')
    return c - 'A' + 10;
  return -1;
}

bool parseHex(const std::string& hex, std::string& out) {
  if (hex.size() % 2 != 0)
    return false;
  out.reserve(out.size() + hex.size() / 2);
  for (std::size_t i = 0; i < hex.size(); i += 2) {
    const int hi = hexValue(hex[i]), lo = hexValue(hex[i + 1]);
    if (hi < 0 || lo < 0)
      return false;
    out.push_back(static_cast<char>(hi * 16 + lo));
  }
  return true;
}

bool splitSessionLine(const std::string& line, double& seconds, std::string& hex) {
  std::istringstream in(line);
  std::string time_text, extra;
  if (!(in >> time_text >> hex) || (in >> extra))
    return false;
  try {
    std::size_t used = 0;
    seconds = std::stod(time_text, &used);
    return used == time_text.size();
  } catch (const std::exception&) {
    return false;
  }
}

bool isDataLine(const std::string& line) {
  const auto first = line.find_first_not_of(" \t\r");
  return first != std::string::npos && line[first] != '#';
}

// Records a failed frame, folding it into the previous entry when that one failed too.
void addFailure(std::vector<CapturedTelegram>& out, std::size_t offset, std::string error) {
  if (!out.empty() && !out.back().error.empty()) {
    ++out.back().failures;
    out.back().last_offset = offset;
    return;
  }
  CapturedTelegram t;
  t.offset = t.last_offset = offset;
  t.error = std::move(error);
  out.push_back(std::move(t));
}

}  // namespace

std::string readRecording(const std::string& path, const std::string& what) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw Error(ErrorCode::FILE_NOT_FOUND, what + " " + path + " is a directory, not a file");
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw Error(ErrorCode::FILE_NOT_FOUND, "cannot open " + what + " " + path);
  try {
    return std::string(std::istreambuf_iterator<char>(in), {});
  } catch (const std::exception& e) {
    throw Error(ErrorCode::FILE_NOT_FOUND, "cannot read " + what + " " + path + ": " + e.what());
  }
}

std::vector<CapturedTelegram> cutColaBStream(const std::string& bytes) {
  std::vector<CapturedTelegram> out;
  std::size_t pos = bytes.find(COLA_B_MAGIC);
  while (pos != std::string::npos) {
    if (bytes.size() - pos < COLA_B_HEADER_BYTES) {
      addFailure(out, pos, "cut-off frame (no length field)");
      break;
    }
    const std::uint64_t length = colaBDeclaredLength(bytes.data() + pos);
    const std::size_t left = bytes.size() - pos - COLA_B_HEADER_BYTES;
    if (length + 1 > left) {
      addFailure(out, pos,
                 "cut-off frame (" + std::to_string(length) + " payload bytes declared, " +
                     std::to_string(left) + " left)");
      // A corrupt length can swallow good frames: resynchronise just past this magic.
      pos = bytes.find(COLA_B_MAGIC, pos + 1);
      continue;
    }
    const char* payload = bytes.data() + pos + COLA_B_HEADER_BYTES;
    if (colaBChecksum(payload, length) != payload[length]) {
      addFailure(out, pos, "bad checksum");
      pos = bytes.find(COLA_B_MAGIC, pos + 1);
      continue;
    }
    const std::size_t end = pos + COLA_B_HEADER_BYTES + length + 1;
    CapturedTelegram t;
    t.offset = t.last_offset = pos;
    t.payload.assign(payload, length);
    out.push_back(std::move(t));
    pos = bytes.find(COLA_B_MAGIC, end);
  }
  return out;
}

std::vector<CapturedTelegram> cutColaAStream(const std::string& bytes) {
  std::vector<CapturedTelegram> out;
  std::size_t pos = bytes.find(STX);
  while (pos != std::string::npos) {
    const std::size_t end = bytes.find_first_of(std::string{STX, ETX}, pos + 1);
    if (end == std::string::npos || bytes[end] == STX) {
      addFailure(out, pos,
                 "cut-off telegram (no ETX before the " +
                     std::string(end == std::string::npos ? "end" : "next STX") + ")");
      pos = end;
      continue;
    }
    CapturedTelegram t;
    t.offset = t.last_offset = pos;
    t.payload = bytes.substr(pos + 1, end - pos - 1);
    out.push_back(std::move(t));
    pos = bytes.find(STX, end + 1);
  }
  return out;
}

bool isSessionText(const std::string& text) {
  std::istringstream in(text);
  std::string line;
  while (std::getline(in, line)) {
    if (!isDataLine(line))
      continue;
    double seconds = 0;
    std::string hex, bytes;
    return splitSessionLine(line, seconds, hex) && parseHex(hex, bytes);
  }
  return false;
}

std::vector<CapturedTelegram> readSessionText(const std::string& text) {
  // The stream is the lines' bytes in order; each frame takes the time of the line it starts on.
  std::string stream;
  std::vector<std::pair<std::size_t, double>> line_starts;
  std::istringstream in(text);
  std::string line;
  for (int number = 1; std::getline(in, line); ++number) {
    if (!isDataLine(line))
      continue;
    double seconds = 0;
    std::string hex;
    line_starts.emplace_back(stream.size(), 0.0);
    if (!splitSessionLine(line, seconds, hex) || !parseHex(hex, stream)) {
      throw Error(ErrorCode::PARSE_ERROR,
                  "session line " + std::to_string(number) + " is not '<seconds> <hex bytes>'");
    }
    line_starts.back().second = seconds;
  }
  auto telegrams = cutColaBStream(stream);
  std::size_t current = 0;
  for (auto& t : telegrams) {
    while (current + 1 < line_starts.size() && line_starts[current + 1].first <= t.offset)
      ++current;
    if (!line_starts.empty())
      t.time_s = line_starts[current].second;
  }
  return telegrams;
}

bool isRequestType(const std::string& type) {
  return type == "sRN" || type == "sWN" || type == "sMN" || type == "sEN";
}

std::pair<std::string, std::string> commandWords(const std::string& payload) {
  const std::size_t a = payload.find(' ');
  if (a == std::string::npos || a == 0)
    return {};
  std::size_t b = payload.find(' ', a + 1);
  if (b == std::string::npos)
    b = payload.size();
  if (b == a + 1)
    return {};
  return {payload.substr(0, a), payload.substr(a + 1, b - a - 1)};
}

std::string telegramText(const std::string& data) {
  if (data.find(STX) != std::string::npos) {
    ColaAFramer framer;
    framer.feed(data);
    const auto telegram = framer.next();
    if (!telegram)
      throw Error(ErrorCode::PARSE_ERROR, "an STX without its ETX");
    return *telegram;
  }
  std::string text = data;
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r' || text.back() == ' '))
    text.pop_back();
  return text;
}

std::string readTelegramFile(const std::string& path) {
  return telegramText(readRecording(path, "telegram file"));
}

std::vector<CapturedTelegram> readSessionFile(const std::string& path) {
  return readSessionText(readRecording(path, "session file"));
}

}  // namespace lms111
}  // namespace dormant_tree_modeling
