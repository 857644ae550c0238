#pragma once

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "dormant_tree_modeling/lms111/cola.h"

namespace dormant_tree_modeling {
namespace lms111 {

/// @brief The smallest raw DIST value that is a distance: 0 means no echo, 1 ... 15 are the
/// device's codes for an invalid measurement (1: dazzled; the rest reserved).
constexpr std::uint16_t FIRST_VALID_DISTANCE = 16;

/// @brief One data channel of an `LMDscandata` telegram (DIST1, RSSI1, ...).
struct ScanChannel {
  std::string name;
  float scale = 1.0f;  ///< value x scale + offset is the measurement (mm for DIST)
  float offset = 0.0f;
  std::int32_t start_angle = 0;    ///< 1/10000 deg, device convention (-45 ... 225 deg)
  std::uint16_t angular_step = 0;  ///< 1/10000 deg
  std::vector<std::uint16_t> values;

  double startAngleDeg() const { return start_angle / 10000.0; }
  double stepDeg() const { return angular_step / 10000.0; }
};

/// @brief Encoder block entry.
struct ScanEncoder {
  std::uint32_t position = 0;
  std::uint16_t speed = 0;
};

/// @brief Optional time stamp block.
struct ScanTimestamp {
  std::uint16_t year = 0;
  std::uint8_t month = 0, day = 0, hour = 0, minute = 0, second = 0;
  std::uint32_t microsecond = 0;
};

/// @brief Optional event block.
struct ScanEvent {
  std::string type;  ///< 4 characters, e.g. FDIN
  std::uint32_t encoder_position = 0;
  std::uint32_t time_us = 0;
  std::int32_t angle = 0;  ///< 1/10000 deg
};

/// @brief Optional position block: sensor pose as configured in the device.
struct ScanPosition {
  float x = 0, y = 0, z = 0, rot_x = 0, rot_y = 0, rot_z = 0;
  std::uint8_t rotation_type = 0;
};

/// @brief A decoded `LMDscandata` telegram (docs/protocols.md lists the fields in order).
struct ScanTelegram {
  std::string command_type;  ///< sSN (stream) or sRA (polled)
  std::uint16_t version = 0;
  std::uint16_t device_number = 0;
  std::uint32_t serial_number = 0;
  std::uint8_t status_code = 0;    ///< first status token
  std::uint8_t device_status = 0;  ///< 0 ok, 1 error, 2 pollution warning, 5 pollution error
  std::uint16_t telegram_counter = 0;
  std::uint16_t scan_counter = 0;
  std::uint32_t time_since_startup_us = 0;
  std::uint32_t time_of_transmission_us = 0;
  std::uint16_t digital_inputs[2] = {0, 0};
  std::uint16_t digital_outputs[2] = {0, 0};
  std::uint16_t reserved = 0;
  std::uint32_t scan_frequency = 0;         ///< 1/100 Hz
  std::uint32_t measurement_frequency = 0;  ///< 100 Hz units (ray rate)
  std::vector<ScanEncoder> encoders;
  std::vector<ScanChannel> channels16;
  std::vector<ScanChannel> channels8;
  std::optional<ScanPosition> position;
  std::optional<std::string> device_name;
  std::optional<std::string> comment;
  std::optional<ScanTimestamp> timestamp;
  std::optional<ScanEvent> event;

  /// @brief The channel of that name, 16-bit or 8-bit (RSSI1 comes as 8-bit values when
  /// `LMDscandatacfg` asked for 8-bit remission), if present.
  const ScanChannel* channel(const std::string& name) const;
  double scanFrequencyHz() const { return scan_frequency / 100.0; }
  /// @brief Time between two rays, s (1 / (measurement frequency x 100 Hz)).
  double timeIncrement() const {
    return measurement_frequency > 0 ? 1.0 / (100.0 * measurement_frequency) : 0.0;
  }
};

/// @brief Whether a payload (either protocol) is a scan, `sSN` or `sRA LMDscandata`, as opposed
/// to the replies and events a device interleaves with scans.
bool isScanTelegram(const std::string& payload);

/// @brief Decode an `LMDscandata` telegram payload (without STX/ETX or the CoLa-B frame) by
/// walking its structure: any number of encoders and channels, the optional blocks, strings
/// with spaces. CoLa-B carries the same fields big-endian with these widths: version, device
/// number, counters, digital inputs/outputs 2 x 8 bit, reserved, counts, angular step and flags
/// 16 bit; serial, times, frequencies, encoder position 32 bit; channel names 5 and event types
/// 4 characters; scale, offset IEEE-754; start angle int32; values 16 or 8 bit.
/// @throws Error PARSE_ERROR with the field and position for a telegram that is not
///         `LMDscandata`, is cut short, has a non-number where a number belongs, a count that
///         does not match the values, or text left over at the end
ScanTelegram parseScanTelegram(const std::string& payload, Protocol protocol = Protocol::COLA_A);

/// @brief Encode a scan as the device sends it (payload without framing); the inverse of
/// parseScanTelegram, used by the emulator and for round-trip tests.
/// @throws Error INVALID_ARGUMENT when a value does not fit its field (e.g. a CoLa-B channel
///         name that is not 5 characters)
std::string encodeScanTelegram(const ScanTelegram& scan, Protocol protocol = Protocol::COLA_A);

/// @brief The telegram as JSON: every header field, each channel with its name, scale, offset,
/// start angle and step in degrees, count and values (scripts/lms111_decode).
std::string scanTelegramToJson(const ScanTelegram& scan);

}  // namespace lms111
}  // namespace dormant_tree_modeling
