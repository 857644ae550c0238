#include "dormant_tree_modeling/common/config_table.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/lms111/driver.h"

namespace dormant_tree_modeling {
namespace lms111 {

namespace {

constexpr const char* WHAT = "lms111 driver parameter";

ConfigTable<DriverConfig> makeDriverTable() {
  using D = DriverConfig;
  ConfigTable<D> t(WHAT, "");
  t.add("host", &D::host, "The device's address (the LMS111's factory address).")
      .add("port", &D::port, 1, 65535, "2111 CoLa-A, 2112 CoLa-B.")
      .names("protocol", &D::protocol, {{"cola_a", Protocol::COLA_A}, {"cola_b", Protocol::COLA_B}},
             "Telegram framing; must match the port.")
      .add("scan_frequency_hz", &D::scan_frequency_hz, 25.0, 50.0,
           "25 (with 0.25 deg) or 50 (with 0.5 deg).")
      .formerly("scan_frequency")
      .add("angular_resolution_deg", &D::angular_resolution_deg, 0.25, 0.5, "0.25 or 0.5.")
      .formerly("angular_resolution")
      .add("start_angle_deg", &D::start_angle_deg, -45.0, 225.0,
           "First beam, in the device's convention (0 down, 90 ahead, 180 up).")
      .formerly("start_angle")
      .add("stop_angle_deg", &D::stop_angle_deg, -45.0, 225.0,
           "Last beam (inclusive); 1081 beams at 0.25 deg over -45 to 225.")
      .formerly("stop_angle")
      .add("rssi", &D::rssi, "Request the echo strength (published as intensities).")
      .add("connect_timeout_s", &D::connect_timeout_s, 0.01, 600.0, "TCP connect.")
      .formerly("connect_timeout")
      .add("reply_timeout_s", &D::reply_timeout_s, 0.01, 600.0,
           "Per request of the start-up sequence.")
      .formerly("reply_timeout")
      .add("scan_timeout_periods", &D::scan_timeout_periods, 2.0, 1000.0,
           "No scan within this many scan periods: reconnect.")
      .add("ready_timeout_s", &D::ready_timeout_s, 0.01, 600.0,
           "For the first scan after the stream is switched on (motor spin-up).")
      .formerly("ready_timeout")
      .add("reconnect_min_s", &D::reconnect_min_s, 0.001, 600.0,
           "First back-off after a failure; doubles per failure.")
      .formerly("reconnect_min")
      .add("reconnect_max_s", &D::reconnect_max_s, 0.001, 3600.0, "Longest back-off.")
      .formerly("reconnect_max");
  return t;
}

ConfigTable<DriverNodeConfig> makeNodeTable() {
  using N = DriverNodeConfig;
  ConfigTable<N> t(WHAT, "");
  t.include("", &N::device, driverConfigTable())
      .add("frame_id", &N::frame_id, "Frame of the published scans.")
      .add("range_min_m", &N::range_min_m, 0.0, 100.0,
           "Datasheet; nearer returns are published as -Inf (REP 117).")
      .formerly("range_min")
      .add("range_max_m", &N::range_max_m, 0.01, 1000.0,
           "Datasheet (10 % reflectance); farther returns are published as +Inf.")
      .formerly("range_max");
  return t;
}

}  // namespace

const ConfigTable<DriverConfig>& driverConfigTable() {
  static const ConfigTable<DriverConfig> table = makeDriverTable();
  return table;
}

const ConfigTable<DriverNodeConfig>& driverNodeConfigTable() {
  static const ConfigTable<DriverNodeConfig> table = makeNodeTable();
  return table;
}

void DriverConfig::validate() const {
  driverConfigTable().check(*this);
  driverConfigTable().require(!host.empty(), "host must not be empty");
  driverConfigTable().require(
      (scan_frequency_hz == 25.0 && angular_resolution_deg == 0.25) ||
          (scan_frequency_hz == 50.0 && angular_resolution_deg == 0.5),
      "scan_frequency_hz and angular_resolution_deg: the LMS111 runs 25 Hz with 0.25 deg "
      "or 50 Hz with 0.5 deg (asked: " +
          std::to_string(scan_frequency_hz) + " Hz, " + std::to_string(angular_resolution_deg) +
          " deg)");
  driverConfigTable().require(start_angle_deg < stop_angle_deg,
                              "start_angle_deg must be below stop_angle_deg");
  driverConfigTable().require(
      (stopUnits() - startUnits()) % static_cast<std::int64_t>(resolutionUnits()) == 0,
      "stop_angle_deg - start_angle_deg must be a multiple of the resolution");
  driverConfigTable().require(reconnect_max_s >= reconnect_min_s,
                              "reconnect_max_s must be at least reconnect_min_s");
}

void DriverNodeConfig::validate() const {
  device.validate();
  driverNodeConfigTable().check(*this);
  driverNodeConfigTable().require(range_max_m > range_min_m, "range_max_m must exceed range_min_m");
}

}  // namespace lms111
}  // namespace dormant_tree_modeling
