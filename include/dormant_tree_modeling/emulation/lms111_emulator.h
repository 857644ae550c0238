#pragma once

#include <cstdint>
#include <functional>
#include <map>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "dormant_tree_modeling/emulation/scan_source.h"
#include "dormant_tree_modeling/lms111/cola.h"
#include "dormant_tree_modeling/lms111/cola_fields.h"
#include "dormant_tree_modeling/lms111/scan_telegram.h"

namespace dormant_tree_modeling {
namespace emulation {

/// @brief Scan configuration as the device holds it, in the device's units.
struct DeviceScanConfig {
  std::uint32_t frequency = 2500;      ///< 1/100 Hz
  std::uint32_t resolution = 2500;     ///< 1/10000 deg
  std::int32_t start_angle = -450000;  ///< 1/10000 deg, first beam
  std::int32_t stop_angle = 2250000;   ///< 1/10000 deg, last beam (inclusive)

  /// @brief Beams per scan.
  int count() const { return static_cast<int>((stop_angle - start_angle) / resolution) + 1; }
};

/// @brief What `LMDscandatacfg` selects for the scan telegrams.
struct DataOutputConfig {
  bool rssi = false;
  bool rssi_16bit = false;  ///< RSSI1 among the 16-bit channels; else among the 8-bit ones
  bool device_name = false;
  bool comment = false;
  bool time_stamp = false;
  std::uint16_t output_interval = 1;  ///< send every n-th scan
};

/// @brief Failures an emulated device can be told to show, for tests. Counts refer to scan
/// telegrams sent since the emulator (re)started; 0 switches a fault off.
struct LmsFaults {
  std::size_t drop_after = 0;   ///< close every connection once after this many telegrams
  std::size_t stall_after = 0;  ///< then send nothing (and answer nothing) for stall_seconds
  double stall_seconds = 2.0;
  std::size_t trickle_bytes = 0;  ///< write telegrams in pieces of this many bytes
  std::size_t corrupt_every = 0;  ///< flip one byte in every n-th telegram
  std::size_t restart_after = 0;  ///< reboot: close everything, reset, listen again after
  double restart_seconds = 1.0;   ///< restart_seconds
  /// Command name -> sFA code to answer instead, and how often (< 0: always).
  struct SfaFault {
    int code = 0;
    int times = 1;
  };
  std::map<std::string, SfaFault> sfa;

  /// @brief Add an sFA fault from "NAME:CODE[:TIMES]", e.g. "mLMPsetscancfg:8:2".
  /// @throws Error INVALID_ARGUMENT for a malformed specification
  void addSfa(const std::string& specification);
};

/// @brief Identity and timing of an emulated device.
struct LmsEmulatorConfig {
  std::uint32_t serial_number = 0x00A037B9;
  std::string device_name = "LMS111-10100";
  std::string firmware_version = "V1.10";
  double spin_up_seconds = 0.3;      ///< LMCstartmeas or Run until ready for measurement, s
  double clock_drift_ppm = 0.0;      ///< device oscillator error against the host clock
  std::uint32_t clock_start_us = 0;  ///< device clock at power-up (set near 2^32 to test wrap)
  DeviceScanConfig scan;             ///< the configuration it powers up with
  /// Real units answer `LMPoutputRange` a few 1/10000 deg inside the nominal range (-449997 ...
  /// 2249997 on a real LMS111); 0 reports the nominal one.
  std::int32_t reported_angle_error = 0;
};

/// @brief What a recorded CoLa-B session tells an emulated device (SessionReplay builds it):
/// the replies the real device gave, the size of each request it took, and the events it sent.
struct RecordedReplies {
  std::map<std::string, std::string> reply_to;       ///< request payload -> recorded reply
  std::map<std::string, std::size_t> request_bytes;  ///< "sWN LMDscandatacfg" -> payload size
  std::vector<std::string> events;  ///< `sSN` payloads other than scans, in recorded order
};

/// @brief One client connection's view of the device.
struct LmsSession {
  lms111::Protocol protocol = lms111::Protocol::COLA_A;
  int access_level = 0;
  bool streaming = false;
};

/// @brief The device's command interpreter and state machine, without any I/O: the server
/// feeds it request payloads and the time, and sends what it returns. Implements the commands
/// the driver uses (docs/protocols.md): SetAccessMode, mLMPsetscancfg, LMPscancfg,
/// LMPoutputRange, LMDscandatacfg, LMCstartmeas, LMCstopmeas, STlms, Run, DeviceIdent,
/// LMDscandata (event and poll), with `sFA` replies to unknown commands, missing access, wrong
/// state and bad data.
class EmulatedLms111 {
 public:
  /// @param source scan content; shared with the caller
  EmulatedLms111(LmsEmulatorConfig config, std::shared_ptr<ScanSource> source,
                 LmsFaults faults = {});

  /// @brief Replies to one request payload: the reply, preceded by a recorded event when a
  /// recording with events is set.
  /// @param now_s seconds since the emulator started (steady clock)
  std::vector<std::string> handle(const std::string& payload, LmsSession& session, double now_s);

  /// @brief `STlms` state at a time.
  int state(double now_s) const;
  /// @brief Seconds between two scans at the active configuration.
  double scanPeriod() const { return 100.0 / active_.frequency; }
  /// @brief The next scan telegram, its first ray at now_s; advances the counters. Empty
  /// when the device is not ready, or the output interval skips this scan.
  std::optional<lms111::ScanTelegram> nextScan(double now_s);
  /// @brief Device clock (µs since power-up, wrapping at 2^32) at a time.
  std::uint32_t clockUs(double now_s) const;
  /// @brief Reboot: configuration back to the power-up values, counters and clock restart.
  void powerUp(double now_s);

  /// @brief Answer CoLa-B requests from a recording: a request of a recorded command must have
  /// the recorded size (else `sFA` 7 or 8, before any other check), and one identical to a
  /// recorded request gets the recorded reply once the emulator accepted it. Every reply is
  /// preceded by the next recorded event, as a device does whose events a client subscribed.
  void setRecording(RecordedReplies recording) { recording_ = std::move(recording); }
  /// @brief The next recorded event for a connection of that protocol (CoLa-B only), cycling.
  std::optional<std::string> nextEvent(lms111::Protocol protocol);

  const LmsFaults& faults() const { return faults_; }
  const DeviceScanConfig& scanConfig() const { return active_; }
  const DataOutputConfig& outputConfig() const { return output_; }

 private:
  std::string reply(const LmsSession& session, const std::string& type, const std::string& name,
                    const std::function<void(lms111::FieldWriter&)>& fields = {}) const;
  std::string sfa(const LmsSession& session, int code) const;
  std::string answer(const std::string& payload, const std::string& type, const std::string& name,
                     lms111::FieldReader& args, LmsSession& session, double now_s);
  std::string dispatch(const std::string& type, const std::string& name, lms111::FieldReader& args,
                       LmsSession& session, double now_s);

  LmsEmulatorConfig config_;
  std::shared_ptr<ScanSource> source_;
  LmsFaults faults_;
  DeviceScanConfig active_, pending_;
  DataOutputConfig output_;
  bool measuring_ = true;
  double power_up_s_ = 0.0;
  double ready_at_s_ = 0.0;
  std::uint16_t telegram_counter_ = 0, scan_counter_ = 0;
  std::uint64_t scans_ = 0;
  std::optional<RecordedReplies> recording_;
  std::size_t next_event_ = 0;
};

}  // namespace emulation
}  // namespace dormant_tree_modeling
