#include "dormant_tree_modeling/emulation/scan_source.h"

#include <cmath>
#include <fstream>
#include <iterator>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/lms111/capture.h"
#include "dormant_tree_modeling/lms111/cola.h"

namespace dormant_tree_modeling {
namespace emulation {

using namespace lms111;  // the emulator speaks the protocol the real driver speaks

RecordedScanSource::RecordedScanSource(ScanTelegram telegram)
    : RecordedScanSource(std::vector<ScanTelegram>{std::move(telegram)}) {}

RecordedScanSource::RecordedScanSource(std::vector<ScanTelegram> telegrams)
    : telegrams_(std::move(telegrams)) {
  if (telegrams_.empty())
    throw Error(ErrorCode::INVALID_ARGUMENT, "a recorded scan source needs at least one scan");
  for (const auto& t : telegrams_) {
    const ScanChannel* dist = t.channel("DIST1");
    if (!dist || dist->values.empty() || dist->angular_step == 0) {
      throw Error(ErrorCode::INVALID_ARGUMENT,
                  "a recorded scan needs a DIST1 channel with values and a non-zero step");
    }
  }
}

RecordedScanSource RecordedScanSource::fromFile(const std::string& path) {
  return RecordedScanSource(parseScanTelegram(readTelegramFile(path)));
}

ScanContent RecordedScanSource::scan(const ScanGeometry& geometry, double, std::uint64_t index) {
  const ScanTelegram& telegram = telegrams_[index % telegrams_.size()];
  const ScanChannel& dist = *telegram.channel("DIST1");
  const ScanChannel* rssi = telegram.channel("RSSI1");
  ScanContent out;
  out.distances_mm.assign(geometry.count, 0);
  out.rssi.assign(geometry.count, 0);
  const auto n = static_cast<long>(dist.values.size());
  for (int i = 0; i < geometry.count; ++i) {
    const long k = std::lround((geometry.angleDeg(i) - dist.startAngleDeg()) / dist.stepDeg());
    if (k < 0 || k >= n)
      continue;
    out.distances_mm[i] =
        static_cast<std::uint16_t>(std::lround(dist.values[k] * dist.scale + dist.offset));
    if (rssi && k < static_cast<long>(rssi->values.size()))
      out.rssi[i] = rssi->values[k];
    else if (out.distances_mm[i] > 0)
      out.rssi[i] = 200;  // the recording has no echo strength: report a plain bark echo
  }
  return out;
}

}  // namespace emulation
}  // namespace dormant_tree_modeling
