#include "dormant_tree_modeling/lms111/requests.h"

#include "dormant_tree_modeling/lms111/cola_fields.h"

namespace dormant_tree_modeling {
namespace lms111 {

namespace {

// LMPoutputRange's first field: "status code", always 1 for a single-sector output range.
constexpr std::uint16_t OUTPUT_RANGE_STATUS = 1;
// mLMPsetscancfg: the LMS1xx scans one sector.
constexpr std::uint16_t SECTORS = 1;

std::unique_ptr<FieldWriter> start(Protocol protocol, const char* type, const char* name) {
  auto w = makeWriter(protocol);
  w->word(type);
  w->word(name);
  return w;
}

void writeArea(FieldWriter& w, const ScanArea& area) {
  w.unsignedValue(area.resolution);
  w.signedValue(area.start_angle);
  w.signedValue(area.stop_angle);
}

}  // namespace

std::string plainRequest(Protocol protocol, const std::string& type, const std::string& name) {
  return start(protocol, type.c_str(), name.c_str())->payload();
}

std::string loginRequest(Protocol protocol) {
  auto w = start(protocol, "sMN", "SetAccessMode");
  w->unsignedValue(AUTHORISED_CLIENT_LEVEL, 8);
  w->unsignedValue(AUTHORISED_CLIENT_PASSWORD);
  return w->payload();
}

std::string setScanConfigRequest(Protocol protocol, std::uint32_t frequency, const ScanArea& area) {
  auto w = start(protocol, "sMN", "mLMPsetscancfg");
  w->unsignedValue(frequency);
  w->unsignedValue(SECTORS, 16);
  writeArea(*w, area);
  return w->payload();
}

std::string outputRangeRequest(Protocol protocol, const ScanArea& area) {
  auto w = start(protocol, "sWN", "LMPoutputRange");
  w->unsignedValue(OUTPUT_RANGE_STATUS, 16);
  writeArea(*w, area);
  return w->payload();
}

// The output channel and the encoder setting are each two 8-bit values (mask, then a reserved
// 0), not one 16-bit value: 12 fields in CoLa-A, 13 bytes in CoLa-B.
std::string scanDataConfigRequest(Protocol protocol, const ScanDataOutput& o) {
  auto w = start(protocol, "sWN", "LMDscandatacfg");
  w->unsignedValue(o.echo_mask, 8);
  w->unsignedValue(0, 8);
  w->unsignedValue(o.rssi ? 1 : 0, 8);
  w->unsignedValue(o.rssi_16bit ? 1 : 0, 8);
  w->unsignedValue(0, 8);  // remission unit: digits
  w->unsignedValue(0, 8);  // encoder: none
  w->unsignedValue(0, 8);
  w->unsignedValue(0, 8);  // position block: the LMS1xx has none
  w->unsignedValue(o.device_name ? 1 : 0, 8);
  w->unsignedValue(o.comment ? 1 : 0, 8);
  w->unsignedValue(o.time_block ? 1 : 0, 8);
  w->unsignedValue(o.output_interval, 16);
  return w->payload();
}

std::string streamRequest(Protocol protocol, bool on) {
  auto w = start(protocol, "sEN", "LMDscandata");
  w->unsignedValue(on ? 1 : 0, 8);
  return w->payload();
}

}  // namespace lms111
}  // namespace dormant_tree_modeling
