#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "dormant_tree_modeling/lms111/scan_telegram.h"

namespace dormant_tree_modeling {
namespace emulation {

/// @brief The beams of one scan as the device is configured: device angle convention
/// (0 deg down, 90 deg ahead, 180 deg up), first and last beam inclusive.
struct ScanGeometry {
  double start_angle_deg = -45.0;
  double step_deg = 0.25;
  int count = 1081;
  double scan_frequency_hz = 25.0;

  /// @brief Device angle of beam i, deg.
  double angleDeg(int i) const { return start_angle_deg + step_deg * i; }
};

/// @brief What the device measured in one scan.
struct ScanContent {
  std::vector<std::uint16_t> distances_mm;  ///< 0 = no echo
  std::vector<std::uint16_t> rssi;          ///< echo strength 0..255, one per beam
};

/// @brief Where an emulated device's measurements come from.
class ScanSource {
 public:
  virtual ~ScanSource() = default;
  /// @brief The scan taken at `time_s` (s since the device started) with the geometry.
  /// @param index running scan number, for reproducible noise
  virtual ScanContent scan(const ScanGeometry& geometry, double time_s, std::uint64_t index) = 0;
};

/// @brief Replays the DIST1 (and RSSI1, if present) channel of recorded telegrams, one after
/// the other and over again. When the device is configured for other angles than the
/// recording, each beam takes the recorded beam nearest in angle, and beams outside the
/// recorded range report no echo.
class RecordedScanSource : public ScanSource {
 public:
  /// @param telegram a decoded telegram with a DIST1 channel
  /// @throws Error INVALID_ARGUMENT without a DIST1 channel or with an empty one
  explicit RecordedScanSource(lms111::ScanTelegram telegram);
  /// @param telegrams decoded telegrams, each with a DIST1 channel
  /// @throws Error INVALID_ARGUMENT for none, or one without a usable DIST1 channel
  explicit RecordedScanSource(std::vector<lms111::ScanTelegram> telegrams);

  /// @brief Read a CoLa-A telegram from a text file (STX/ETX optional).
  /// @throws Error FILE_NOT_FOUND, PARSE_ERROR
  static RecordedScanSource fromFile(const std::string& path);

  ScanContent scan(const ScanGeometry& geometry, double time_s, std::uint64_t index) override;

 private:
  std::vector<lms111::ScanTelegram> telegrams_;
};

}  // namespace emulation
}  // namespace dormant_tree_modeling
