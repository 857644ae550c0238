// LMS111 telegram throughput: scan telegrams parsed per second for 1081- and 541-beam scans
// (DIST1 + RSSI1) in both protocols, against the device's own rate (25 / 50 Hz; target 100x)
// and against the obvious baseline, a std::istringstream tokenizer with std::stoul (what
// simple drivers do, without any structure check); and the latency from received bytes to
// LaserScan content (framing, parsing, conversion).
#include <benchmark/benchmark.h>

#include <sstream>

#include "dormant_tree_modeling/lms111/cola.h"
#include "dormant_tree_modeling/lms111/laser_scan.h"
#include "dormant_tree_modeling/lms111/scan_telegram.h"
#include "peak_memory.h"

using namespace dormant_tree_modeling;
using namespace dormant_tree_modeling::lms111;

namespace {

// A scan as the driver configures the device: DIST1 and RSSI1 over the full 270 deg.
ScanTelegram scan(int beams) {
  ScanTelegram s;
  s.command_type = "sSN";
  s.version = s.device_number = 1;
  s.serial_number = 0xA037B9;
  s.telegram_counter = 0xC1C3;
  s.scan_counter = 0xC1C6;
  s.time_since_startup_us = 0x12345678;
  s.time_of_transmission_us = 0x12350000;
  s.scan_frequency = beams == 1081 ? 2500 : 5000;
  s.measurement_frequency = 360;
  ScanChannel dist;
  dist.name = "DIST1";
  dist.start_angle = -450000;
  dist.angular_step = beams == 1081 ? 2500 : 5000;
  for (int i = 0; i < beams; ++i)
    dist.values.push_back(static_cast<std::uint16_t>(600 + (i * 37) % 19000));
  ScanChannel rssi = dist;
  rssi.name = "RSSI1";
  for (auto& v : rssi.values)
    v = static_cast<std::uint16_t>(v % 256);
  s.channels16 = {dist, rssi};
  return s;
}

Protocol protocolOf(const benchmark::State& state) {
  return state.range(1) == 0 ? Protocol::COLA_A : Protocol::COLA_B;
}

void BM_ParseScanTelegram(benchmark::State& state) {
  const int beams = static_cast<int>(state.range(0));
  const Protocol protocol = protocolOf(state);
  const std::string payload = encodeScanTelegram(scan(beams), protocol);
  for (auto _ : state)
    benchmark::DoNotOptimize(parseScanTelegram(payload, protocol));
  const double device_hz = beams == 1081 ? 25.0 : 50.0;
  state.counters["telegrams_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.counters["bytes"] = static_cast<double>(payload.size());
  state.counters["device_hz"] = device_hz;
  bench::reportPeakMemory(state);
  state.SetLabel(protocolName(protocol));
}
BENCHMARK(BM_ParseScanTelegram)->ArgsProduct({{1081, 541}, {0, 1}})->Unit(benchmark::kMicrosecond);

// Baseline: split on spaces into strings, convert every token with std::stoul(.., 16).
void BM_BaselineIstringstream(benchmark::State& state) {
  const std::string payload = encodeScanTelegram(scan(static_cast<int>(state.range(0))));
  for (auto _ : state) {
    std::istringstream in(payload);
    std::vector<std::string> tokens;
    std::string t;
    while (in >> t)
      tokens.push_back(t);
    std::vector<unsigned long> values;
    values.reserve(tokens.size());
    for (std::size_t i = 2; i < tokens.size(); ++i) {
      try {
        values.push_back(std::stoul(tokens[i], nullptr, 16));
      } catch (const std::exception&) {
        values.push_back(0);  // channel names
      }
    }
    benchmark::DoNotOptimize(values);
  }
  state.counters["telegrams_per_s"] =
      benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
  state.SetLabel("CoLa-A, no structure check");
}
BENCHMARK(BM_BaselineIstringstream)->Arg(1081)->Arg(541)->Unit(benchmark::kMicrosecond);

void BM_EncodeScanTelegram(benchmark::State& state) {
  const ScanTelegram s = scan(static_cast<int>(state.range(0)));
  const Protocol protocol = protocolOf(state);
  for (auto _ : state)
    benchmark::DoNotOptimize(encodeScanTelegram(s, protocol));
  state.SetLabel(protocolName(protocol));
}
BENCHMARK(BM_EncodeScanTelegram)->ArgsProduct({{1081}, {0, 1}})->Unit(benchmark::kMicrosecond);

// Latency of the driver's own work per scan: the telegram's bytes arrive in 1460-byte TCP
// segments, are framed, parsed and converted to LaserScan content.
void BM_BytesToLaserScan(benchmark::State& state) {
  const int beams = static_cast<int>(state.range(0));
  const Protocol protocol = protocolOf(state);
  const std::string bytes = frame(protocol, encodeScanTelegram(scan(beams), protocol));
  constexpr std::size_t SEGMENT = 1460;
  auto framer = makeFramer(protocol);
  for (auto _ : state) {
    for (std::size_t at = 0; at < bytes.size(); at += SEGMENT)
      framer->feed(bytes.data() + at, std::min(SEGMENT, bytes.size() - at));
    const auto payload = framer->next();
    benchmark::DoNotOptimize(toLaserScan(parseScanTelegram(*payload, protocol), 0.5, 20.0));
  }
  bench::reportPeakMemory(state);
  state.SetLabel(protocolName(protocol));
}
BENCHMARK(BM_BytesToLaserScan)->ArgsProduct({{1081, 541}, {0, 1}})->Unit(benchmark::kMicrosecond);

}  // namespace

BENCHMARK_MAIN();
