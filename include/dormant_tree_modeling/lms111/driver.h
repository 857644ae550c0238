#pragma once

#include <atomic>
#include <cstdint>
#include <functional>
#include <memory>
#include <mutex>
#include <string>
#include <thread>

#include "dormant_tree_modeling/lms111/clock_mapper.h"
#include "dormant_tree_modeling/lms111/cola.h"
#include "dormant_tree_modeling/lms111/scan_telegram.h"

namespace dormant_tree_modeling {

template <typename Config>
class ConfigTable;

namespace lms111 {

/// @brief What the driver asks of the device and how patient it is. Angles in the device's
/// convention (0 down, 90 ahead, 180 up); the ROS scan is rotated by -90 deg.
struct DriverConfig {
  std::string host = "192.168.0.1";  ///< the LMS111's factory address
  int port = 2111;                   ///< 2111 CoLa-A, 2112 CoLa-B
  Protocol protocol = Protocol::COLA_A;
  double scan_frequency_hz = 25.0;       ///< 25 (with 0.25 deg) or 50 (with 0.5 deg)
  double angular_resolution_deg = 0.25;  ///< 0.25 or 0.5
  double start_angle_deg = -45.0;        ///< first beam, >= -45
  double stop_angle_deg = 225.0;         ///< last beam (inclusive), <= 225
  bool rssi = true;                      ///< request the RSSI1 channel (LaserScan intensities)
  double connect_timeout_s = 3.0;
  double reply_timeout_s = 2.0;       ///< per request
  double scan_timeout_periods = 5.0;  ///< no scan within this many periods: reconnect
  double ready_timeout_s = 30.0;      ///< the first scan must come within this (motor spin-up)
  double reconnect_min_s = 0.2;       ///< first back-off; doubles per failure
  double reconnect_max_s = 5.0;

  /// @brief Beams per scan for the configured range.
  int beamCount() const;
  /// @brief Device units: 1/100 Hz, 1/10000 deg.
  std::uint32_t frequencyUnits() const;
  std::uint32_t resolutionUnits() const;
  std::int32_t startUnits() const;
  std::int32_t stopUnits() const;
  /// @throws Error INVALID_ARGUMENT naming the bad field and its allowed values
  void validate() const;
};

/// @brief The driver node's parameters (config/lms111_driver.yaml): the device's, and how its
/// scans are published.
struct DriverNodeConfig {
  DriverConfig device;
  std::string frame_id = "laser";
  double range_min_m = 0.5;   ///< datasheet; nearer returns are published as -Inf (REP 117)
  double range_max_m = 20.0;  ///< datasheet (10 % reflectance); beyond: +Inf
  /// @throws Error INVALID_ARGUMENT naming the bad parameter
  void validate() const;
};

/// @brief The keys of DriverConfig: validation, the node's parameters, docs/configuration.md.
const ConfigTable<DriverConfig>& driverConfigTable();
/// @brief The keys of the driver node: the device's, frame_id and the published range.
const ConfigTable<DriverNodeConfig>& driverNodeConfigTable();

/// @brief Where the driver is in its life cycle.
enum class DriverState { STOPPED, CONNECTING, CONFIGURING, STREAMING, BACKING_OFF };

/// @brief "stopped", "connecting", ...
const char* driverStateName(DriverState state);

/// @brief Counters for diagnostics (since start, unless said otherwise).
struct DriverStatistics {
  DriverState state = DriverState::STOPPED;
  std::uint64_t scans = 0;            ///< scans delivered
  std::uint64_t parse_errors = 0;     ///< telegrams that did not parse
  std::uint64_t discarded_bytes = 0;  ///< framing resynchronisations (bytes or frames)
  std::uint64_t scan_gaps = 0;        ///< scans missing by the device's scan counter
  std::uint64_t events = 0;    ///< other `sSN` events (LIDoutputstate, LFErec, ...), passed over
  std::uint64_t connects = 0;  ///< successful start-ups
  std::uint64_t failures = 0;  ///< start-ups or streams that ended in an error
  std::uint8_t device_status = 0;  ///< last telegram's: 0 ok, 1 error, 2/5 pollution
  std::string device_ident;        ///< DeviceIdent of the connected device
  std::string last_error;          ///< most recent failure, readable
};

/// @brief One scan as delivered: the telegram and its stamp.
struct StampedScan {
  ScanTelegram telegram;
  double stamp_s = 0.0;     ///< host time of the first ray (clock-mapped)
  double received_s = 0.0;  ///< host time the telegram was complete
};

/// @brief The LMS111 Ethernet driver: connects, runs the start-up sequence of
/// docs/protocols.md with every reply checked, verifies that the device streams what was
/// asked, and delivers stamped scans; on any failure (refused connection, timeout, closed
/// socket, silent device, sFA, wrong configuration) it logs one clear message, backs off and
/// starts over, until stop(). Runs in its own thread; callbacks come from that thread.
class Lms111Driver {
 public:
  using ScanCallback = std::function<void(const StampedScan&)>;
  /// Severity 0 info, 1 warning, 2 error.
  using LogCallback = std::function<void(int severity, const std::string&)>;
  /// Host clock, s (ROS time in the node, so that sim time and stamps agree).
  using ClockFunction = std::function<double()>;

  /// @throws Error INVALID_ARGUMENT for a bad configuration
  Lms111Driver(DriverConfig config, ScanCallback on_scan, LogCallback log = {},
               ClockFunction clock = {});
  ~Lms111Driver();
  Lms111Driver(const Lms111Driver&) = delete;
  Lms111Driver& operator=(const Lms111Driver&) = delete;

  /// @brief Start the driver thread (no-op when running).
  void start();
  /// @brief Stop the stream (`sEN LMDscandata 0`), close and join. Idempotent.
  void stop();
  DriverStatistics statistics() const;
  const DriverConfig& config() const { return config_; }

 private:
  class Session;
  void run();
  void setState(DriverState state);
  void log(int severity, const std::string& message);
  bool sleepFor(double seconds);  // false when stopped meanwhile

  DriverConfig config_;
  ScanCallback on_scan_;
  LogCallback log_;
  ClockFunction clock_;
  std::atomic<bool> stopping_{false};
  std::thread thread_;
  mutable std::mutex mutex_;
  DriverStatistics stats_;
  std::string last_logged_error_;
  ClockMapper clock_mapper_;
};

}  // namespace lms111
}  // namespace dormant_tree_modeling
