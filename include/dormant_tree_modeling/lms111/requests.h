#pragma once

#include <cstdint>
#include <string>

#include "dormant_tree_modeling/lms111/cola.h"

namespace dormant_tree_modeling {
namespace lms111 {

/// @brief What `sWN LMDscandatacfg` asks the scan telegrams to carry.
struct ScanDataOutput {
  std::uint8_t echo_mask = 1;  ///< output channel bit mask: 1 first echo, 2 second, 3 both
  bool rssi = true;            ///< RSSI1 channel
  bool rssi_16bit = false;     ///< RSSI values as 16 instead of 8 bits
  bool device_name = false;
  bool comment = false;
  bool time_block = false;            ///< the real-time clock block
  std::uint16_t output_interval = 1;  ///< every n-th scan
};

/// @brief The scan area of `mLMPsetscancfg`, `LMPoutputRange` and `LMPscancfg`, in the device's
/// units.
struct ScanArea {
  std::uint32_t resolution = 2500;     ///< 1/10000 deg
  std::int32_t start_angle = -450000;  ///< 1/10000 deg, first beam
  std::int32_t stop_angle = 2250000;   ///< 1/10000 deg, last beam (inclusive)
};

/// @brief Request payloads (without framing) exactly as the device takes them; their layouts
/// are in docs/protocols.md with what each was checked against.
/// @{
std::string plainRequest(Protocol protocol, const std::string& type, const std::string& name);
std::string loginRequest(Protocol protocol);
std::string setScanConfigRequest(Protocol protocol, std::uint32_t frequency, const ScanArea& area);
std::string outputRangeRequest(Protocol protocol, const ScanArea& area);
std::string scanDataConfigRequest(Protocol protocol, const ScanDataOutput& output);
std::string streamRequest(Protocol protocol, bool on);
/// @}

}  // namespace lms111
}  // namespace dormant_tree_modeling
