// libFuzzer target for everything that reads bytes from the LMS111's socket or from a
// recording: the CoLa-A and CoLa-B framers, the capture cutters and the session reader of
// lms111_decode, the scan telegram parser in both protocols (with an encode/parse round-trip
// property on whatever parses), the LaserScan conversion, the emulated device's command
// interpreter and the session replay device. Built with clang's
// -fsanitize=fuzzer,address,undefined by `make fuzz`.
#include <cstddef>
#include <cstdint>
#include <cstdlib>
#include <cstring>
#include <iostream>
#include <memory>
#include <string>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/emulation/lms111_emulator.h"
#include "dormant_tree_modeling/emulation/session_replay.h"
#include "dormant_tree_modeling/lms111/capture.h"
#include "dormant_tree_modeling/lms111/cola.h"
#include "dormant_tree_modeling/lms111/laser_scan.h"
#include "dormant_tree_modeling/lms111/scan_telegram.h"

using namespace dormant_tree_modeling;
using namespace dormant_tree_modeling::lms111;
using namespace dormant_tree_modeling::emulation;

namespace {

// Scans for the emulated device: a fixed 541-beam pattern, so that no file is needed.
class PatternSource : public ScanSource {
 public:
  ScanContent scan(const ScanGeometry& g, double, std::uint64_t) override {
    ScanContent c;
    for (int i = 0; i < g.count; ++i) {
      c.distances_mm.push_back(static_cast<std::uint16_t>(500 + 7 * i));
      c.rssi.push_back(static_cast<std::uint16_t>(i & 0xFF));
    }
    return c;
  }
};

void parseChecked(const std::string& payload, Protocol protocol) {
  ScanTelegram scan;
  try {
    scan = parseScanTelegram(payload, protocol);
  } catch (const Error&) {
    return;  // rejected with a reason: fine
  }
  // Whatever parses must encode to something that parses to the same encoding.
  std::string once;
  try {
    once = encodeScanTelegram(scan, protocol);
  } catch (const Error&) {
    return;  // e.g. a CoLa-A channel name that CoLa-B's fixed width cannot carry
  }
  const std::string twice = encodeScanTelegram(parseScanTelegram(once, protocol), protocol);
  if (once != twice) {
    std::cerr << "round trip differs\n";
    std::abort();
  }
  try {
    toLaserScan(scan, 0.5, 20.0);
  } catch (const Error&) {
  }
  scanTelegramToJson(scan);
}

// The recording paths: cut as a CoLa-B and a CoLa-A capture and as a session text; every
// telegram found is decoded, and a session that holds a scan is replayed to its own requests.
void recordingChecked(const std::string& bytes) {
  for (const auto& t : cutColaBStream(bytes))
    parseChecked(t.payload, Protocol::COLA_B);
  for (const auto& t : cutColaAStream(bytes))
    parseChecked(t.payload, Protocol::COLA_A);
  std::vector<CapturedTelegram> session;
  try {
    session = readSessionText(bytes);
  } catch (const Error&) {
    return;
  }
  std::shared_ptr<EmulatedLms111> device;
  try {
    device = makeSessionReplay(session);
  } catch (const Error&) {
    return;
  }
  LmsSession s;
  s.protocol = Protocol::COLA_B;
  for (const auto& t : session)
    device->handle(t.payload, s, 1.0);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::string bytes(reinterpret_cast<const char*>(data), size);
  parseChecked(bytes, Protocol::COLA_A);
  parseChecked(bytes, Protocol::COLA_B);
  // The stream in two pieces, split where the first byte says.
  const std::size_t split = size > 0 ? data[0] % (size + 1) : 0;
  for (const Protocol p : {Protocol::COLA_A, Protocol::COLA_B}) {
    auto framer = makeFramer(p, 4096);
    framer->feed(bytes.substr(0, split));
    framer->feed(bytes.substr(split));
    while (auto payload = framer->next())
      parseChecked(*payload, p);
  }
  recordingChecked(bytes);
  sfaCode(Protocol::COLA_A, bytes);
  sfaCode(Protocol::COLA_B, bytes);
  static auto source = std::make_shared<PatternSource>();
  for (const Protocol p : {Protocol::COLA_A, Protocol::COLA_B}) {
    EmulatedLms111 device(LmsEmulatorConfig{}, source);
    LmsSession session;
    session.protocol = p;
    session.access_level = 3;
    for (const auto& reply : device.handle(bytes, session, 1.0))
      parseChecked(reply, p);
  }
  return 0;
}
