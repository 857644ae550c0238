// lms111_decode: decodes recorded LMS1xx telegrams, CoLa-A or CoLa-B, to JSON or a summary.
#include <algorithm>
#include <boost/program_options.hpp>
#include <cstdio>
#include <iostream>
#include <iterator>
#include <string>
#include <vector>

#include "command_line.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/emulation/scan_source.h"
#include "dormant_tree_modeling/lms111/capture.h"
#include "dormant_tree_modeling/lms111/scan_telegram.h"

namespace po = boost::program_options;
using namespace dormant_tree_modeling;
using lms111::CapturedTelegram;
using lms111::Protocol;

namespace {

constexpr int EXIT_USAGE = 2;
constexpr int EXIT_NO_FILE = 3;
constexpr int EXIT_BAD_DATA = 4;

struct Recording {
  Protocol protocol = Protocol::COLA_A;
  const char* form = "";
  std::vector<CapturedTelegram> telegrams;
};

// Session text, a CoLa-B byte stream, a CoLa-A byte stream, or one bare CoLa-A telegram.
Recording cutRecording(const std::string& data) {
  Recording r;
  if (lms111::isSessionText(data)) {
    r.protocol = Protocol::COLA_B;
    r.form = "session";
    r.telegrams = lms111::readSessionText(data);
  } else if (data.find(std::string(4, '\x02')) != std::string::npos) {
    r.protocol = Protocol::COLA_B;
    r.form = "CoLa-B stream";
    r.telegrams = lms111::cutColaBStream(data);
  } else if (data.find(lms111::STX) != std::string::npos) {
    r.form = "CoLa-A stream";
    r.telegrams = lms111::cutColaAStream(data);
  } else {
    r.form = "CoLa-A telegram";
    CapturedTelegram t;
    t.payload = lms111::telegramText(data);
    r.telegrams.push_back(t);
  }
  return r;
}

std::string where(const CapturedTelegram& t) {
  char buf[64];
  if (t.time_s >= 0)
    std::snprintf(buf, sizeof buf, "@%zu t=%.6f", t.offset, t.time_s);
  else
    std::snprintf(buf, sizeof buf, "@%zu", t.offset);
  return buf;
}

std::string summaryOf(const lms111::ScanTelegram& s) {
  std::string line =
      " telegram " + std::to_string(s.telegram_counter) + " scan " + std::to_string(s.scan_counter);
  char buf[160];
  std::snprintf(buf, sizeof buf, " %.2f Hz", s.scanFrequencyHz());
  line += buf;
  const lms111::ScanChannel* dist = s.channel("DIST1");
  if (!dist || dist->values.empty())
    return line + " no DIST1";
  double lo = -1, hi = -1;
  for (const auto v : dist->values) {
    const double mm = v * dist->scale + dist->offset;
    if (v < lms111::FIRST_VALID_DISTANCE)
      continue;  // no echo, or a code for an invalid measurement
    lo = lo < 0 ? mm : std::min(lo, mm);
    hi = std::max(hi, mm);
  }
  const double last = dist->startAngleDeg() + dist->stepDeg() * (dist->values.size() - 1);
  std::snprintf(buf, sizeof buf, " %zu beams %.4f..%.4f deg range %.0f..%.0f mm",
                dist->values.size(), dist->startAngleDeg(), last, lo, hi);
  return line + buf;
}

// One telegram: a summary line, or its JSON when it is a scan. False when it should have
// decoded and did not.
bool decodeOne(const CapturedTelegram& t, Protocol protocol, bool summary, bool bare) {
  if (!lms111::isScanTelegram(t.payload) && !bare) {
    const auto [type, name] = lms111::commandWords(t.payload);
    if (summary)
      std::cout << where(t) << " " << type << " " << printableBytes(name, 40) << "\n";
    return true;
  }
  try {
    const auto s = lms111::parseScanTelegram(t.payload, protocol);
    if (summary)
      std::cout << where(t) << " " << s.command_type << " LMDscandata" << summaryOf(s) << "\n";
    else
      std::cout << lms111::scanTelegramToJson(s);
    return true;
  } catch (const Error& e) {
    std::cerr << "lms111_decode: " << where(t) << ": " << e.what() << "\n";
    return false;
  }
}

int decodeAll(const std::string& data, bool summary) {
  const Recording r = cutRecording(data);
  const bool bare = r.telegrams.size() == 1 && r.telegrams.front().error.empty();
  std::size_t good = 0, bad = 0;
  for (const auto& t : r.telegrams) {
    if (!t.error.empty()) {
      std::cerr << "lms111_decode: " << where(t) << ": " << t.error;
      if (t.failures > 1) {
        std::cerr << " (and " << t.failures - 1 << " more failed frames up to offset "
                  << t.last_offset << ")";
      }
      std::cerr << "\n";
      bad += t.failures;
    } else if (decodeOne(t, r.protocol, summary, bare)) {
      ++good;
    } else {
      ++bad;
    }
  }
  if (summary) {
    std::cout << r.form << " (" << lms111::protocolName(r.protocol) << "): " << good
              << " telegrams decoded, " << bad << " failed\n";
  }
  if (good == 0 && bad == 0)
    std::cerr << "lms111_decode: no telegram in the input\n";
  return bad == 0 && good > 0 ? 0 : EXIT_BAD_DATA;
}

}  // namespace

int main(int argc, char** argv) {
  std::string path;
  bool summary = false;
  po::options_description desc(
      "Usage: lms111_decode [--summary] FILE\n"
      "Decodes recorded LMDscandata telegrams and prints each as JSON (header fields, channels "
      "with name, scale, offset, start angle and step in degrees, count and values). FILE ('-': "
      "standard input) holds one CoLa-A telegram (STX/ETX optional), a CoLa-A or CoLa-B byte "
      "stream (a capture), or a session in '<seconds> <hex>' lines. A bad checksum or a cut-off "
      "frame is reported with its byte offset and decoding goes on. Exit 0: every telegram "
      "decoded; 2: bad command line; 3: no such file; 4: a telegram failed or there was none");
  desc.add_options()("help,h", "this help")(
      "summary", po::bool_switch(&summary),
      "one line per telegram: offset, type and name; for scans the counters, frequency, beams, "
      "first and last angle, least and greatest range")("file", po::value(&path)->required(),
                                                        "the recording");
  po::positional_options_description positional;
  positional.add("file", 1);
  try {
    po::variables_map vm;
    if (tools::parseOrHelp(argc, argv, desc, vm, positional))
      return 0;
    const std::string data = path == "-" ? std::string(std::istreambuf_iterator<char>(std::cin), {})
                                         : lms111::readRecording(path, "recording");
    return decodeAll(data, summary);
  } catch (const po::error& e) {
    std::cerr << "lms111_decode: " << e.what() << "\n" << desc << "\n";
    return EXIT_USAGE;
  } catch (const Error& e) {
    std::cerr << "lms111_decode: " << errorCodeName(e.code()) << ": " << e.what() << "\n";
    return e.code() == ErrorCode::FILE_NOT_FOUND ? EXIT_NO_FILE : EXIT_BAD_DATA;
  } catch (const std::exception& e) {
    return tools::reportUnexpected("lms111_decode", e);
  }
}
