// The driver against the emulator on 127.0.0.1: the start-up sequence, both protocols, and
// recovery from the faults users of existing drivers report.
#include <gtest/gtest.h>

#include <algorithm>
#include <chrono>
#include <cmath>
#include <condition_variable>
#include <mutex>
#include <thread>
#include <vector>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/emulation/lms111_server.h"
#include "dormant_tree_modeling/lms111/driver.h"

namespace dormant_tree_modeling {
namespace lms111 {
namespace {

using namespace emulation;  // the tests run the driver against the device emulators

using Seconds = std::chrono::duration<double>;

std::shared_ptr<ScanSource> recorded() {
  return std::make_shared<RecordedScanSource>(RecordedScanSource::fromFile(
      std::string(DTM_SHARED_DATA_DIR) + "/lms1xx/lms1xx_scan_541pts.txt"));
}

// Collects what the driver delivers and logs.
struct Sink {
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<StampedScan> scans;
  std::vector<std::string> logs;

  Lms111Driver::ScanCallback onScan() {
    return [this](const StampedScan& s) {
      std::lock_guard<std::mutex> lock(mutex);
      scans.push_back(s);
      changed.notify_all();
    };
  }
  Lms111Driver::LogCallback onLog() {
    return [this](int, const std::string& m) {
      std::lock_guard<std::mutex> lock(mutex);
      logs.push_back(m);
    };
  }
  // Waits until `n` scans arrived in total; false on timeout.
  bool waitFor(std::size_t n, double timeout_s) {
    std::unique_lock<std::mutex> lock(mutex);
    return changed.wait_for(lock, Seconds(timeout_s), [&] { return scans.size() >= n; });
  }
  bool logged(const std::string& part) {
    std::lock_guard<std::mutex> lock(mutex);
    for (const auto& l : logs) {
      if (l.find(part) != std::string::npos)
        return true;
    }
    return false;
  }
};

struct Bench {
  explicit Bench(LmsFaults faults = {}, double frequency_hz = 50.0) {
    LmsEmulatorConfig c;
    c.spin_up_seconds = 0.05;
    c.scan.frequency = c.scan.resolution = frequency_hz == 50.0 ? 5000 : 2500;
    device = std::make_shared<EmulatedLms111>(c, recorded(), faults);
    LmsServerConfig o;
    o.cola_a_port = 0;
    o.cola_b_port = 0;
    server = std::make_unique<LmsServer>(device, o);
  }
  DriverConfig driverConfig(Protocol protocol = Protocol::COLA_A) const {
    DriverConfig d;
    d.host = "127.0.0.1";
    d.protocol = protocol;
    d.port = protocol == Protocol::COLA_A ? server->colaAPort() : server->colaBPort();
    d.scan_frequency_hz = 50.0;
    d.angular_resolution_deg = 0.5;
    d.reply_timeout_s = 0.5;
    d.reconnect_min_s = 0.05;
    d.reconnect_max_s = 0.2;
    return d;
  }
  std::shared_ptr<EmulatedLms111> device;
  std::unique_ptr<LmsServer> server;
};

TEST(Lms111Driver, StreamsTheRequestedScansInBothProtocols) {
  for (const Protocol p : {Protocol::COLA_A, Protocol::COLA_B}) {
    Bench bench;
    Sink sink;
    DriverConfig config = bench.driverConfig(p);
    config.start_angle_deg = 0.0;  // a narrower range than the device's 270 deg
    config.stop_angle_deg = 180.0;
    Lms111Driver driver(config, sink.onScan(), sink.onLog());
    driver.start();
    ASSERT_TRUE(sink.waitFor(20, 5.0)) << protocolName(p);
    driver.stop();
    const DriverStatistics st = driver.statistics();
    EXPECT_EQ(st.state, DriverState::STOPPED);
    EXPECT_EQ(st.failures, 0u) << st.last_error;
    EXPECT_EQ(st.parse_errors, 0u);
    EXPECT_EQ(st.scan_gaps, 0u);
    EXPECT_NE(st.device_ident.find("LMS111"), std::string::npos);
    std::lock_guard<std::mutex> lock(sink.mutex);
    std::size_t on_device_clock = 0;
    std::vector<double> device_steps;
    for (std::size_t i = 0; i < sink.scans.size(); ++i) {
      const ScanTelegram& t = sink.scans[i].telegram;
      ASSERT_NE(t.channel("DIST1"), nullptr);
      EXPECT_EQ(t.channel("DIST1")->values.size(), 361u);  // 0 ... 180 deg at 0.5 deg
      EXPECT_EQ(t.channel("DIST1")->start_angle, 0);
      EXPECT_NE(t.channel("RSSI1"), nullptr);
      // The first ray was measured before the telegram was sent (3/4 of a turn, 15 ms), and
      // the telegram sent before it arrived.
      const double measuring_s = 1e-6 * (t.time_of_transmission_us - t.time_since_startup_us);
      EXPECT_LE(sink.scans[i].stamp_s, sink.scans[i].received_s - measuring_s + 1e-3);
      // On the host clock, not the device's: a second covers any stall of a loaded machine.
      EXPECT_GT(sink.scans[i].stamp_s, sink.scans[i].received_s - 1.0);
      if (i > 0) {
        // Stamps step as the device clock does; only the lower envelope of the transfer
        // delays moves them, and only earlier: when a scan arrives faster than every one
        // before it. How far apart the device stamped two scans is the emulator's schedule,
        // which a stalled host stretches, so the bound is relative to the device clock.
        const double device_step =
            1e-6 * (t.time_since_startup_us - sink.scans[i - 1].telegram.time_since_startup_us);
        const double step = sink.scans[i].stamp_s - sink.scans[i - 1].stamp_s;
        EXPECT_LE(step, device_step + 1e-3);
        on_device_clock += std::abs(step - device_step) <= 1e-3;
        device_steps.push_back(device_step);
      }
    }
    EXPECT_GE(on_device_clock, (sink.scans.size() - 1) * 3 / 4) << protocolName(p);
    std::nth_element(device_steps.begin(), device_steps.begin() + device_steps.size() / 2,
                     device_steps.end());
    EXPECT_NEAR(device_steps[device_steps.size() / 2], 0.02, 1e-3);  // 50 Hz
  }
}

TEST(Lms111Driver, ReconnectsAfterTheDeviceDropsTheConnectionOrGoesSilent) {
  LmsFaults faults;
  faults.drop_after = 10;
  faults.stall_after = 30;
  faults.stall_seconds = 1.0;
  Bench bench(faults);
  Sink sink;
  Lms111Driver driver(bench.driverConfig(), sink.onScan(), sink.onLog());
  driver.start();
  ASSERT_TRUE(sink.waitFor(45, 8.0));
  driver.stop();
  const DriverStatistics st = driver.statistics();
  EXPECT_GE(st.failures, 2u);  // the drop and the read timeout
  EXPECT_GE(st.connects, 3u);
  EXPECT_TRUE(sink.logged("closed the connection")) << st.last_error;
  EXPECT_TRUE(sink.logged("no scan within"));
  EXPECT_GE(bench.server->connectionsAccepted(), 3u);
}

TEST(Lms111Driver, SurvivesTrickledAndCorruptedBytes) {
  for (const Protocol p : {Protocol::COLA_A, Protocol::COLA_B}) {
    LmsFaults faults;
    faults.trickle_bytes = 500;
    faults.corrupt_every = 4;
    Bench bench(faults);
    Sink sink;
    Lms111Driver driver(bench.driverConfig(p), sink.onScan(), sink.onLog());
    driver.start();
    ASSERT_TRUE(sink.waitFor(12, 8.0)) << protocolName(p);
    driver.stop();
    const DriverStatistics st = driver.statistics();
    // CoLa-A: the flipped byte breaks a field; CoLa-B: the checksum drops the frame.
    EXPECT_GT(st.parse_errors + st.discarded_bytes, 0u) << protocolName(p);
    EXPECT_GT(st.scan_gaps, 0u);
  }
}

TEST(Lms111Driver, SfaOnConfigurationGivesAClearErrorAndARetry) {
  // The device powers up at 25 Hz and refuses the first mLMPsetscancfg (as some firmware
  // does after power-up): the driver finds it running the wrong configuration, says so,
  // and succeeds on the next attempt.
  LmsFaults faults;
  faults.addSfa("mLMPsetscancfg:4:1");
  Bench bench(faults, 25.0);
  Sink sink;
  Lms111Driver driver(bench.driverConfig(), sink.onScan(), sink.onLog());
  driver.start();
  ASSERT_TRUE(sink.waitFor(5, 5.0));
  driver.stop();
  EXPECT_TRUE(sink.logged("refused sMN mLMPsetscancfg with sFA 4: local condition failed"));
  EXPECT_TRUE(sink.logged("the device runs 25 Hz / 0.25 deg, not the requested 50 Hz / 0.5 deg"));
  EXPECT_EQ(driver.statistics().failures, 1u);
  std::lock_guard<std::mutex> lock(sink.mutex);
  EXPECT_EQ(sink.scans.back().telegram.scan_frequency, 5000u);
}

TEST(Lms111Driver, RecoversFromADeviceRebootAndResetsTheClock) {
  LmsFaults faults;
  faults.restart_after = 10;
  faults.restart_seconds = 0.3;
  Bench bench(faults);
  Sink sink;
  Lms111Driver driver(bench.driverConfig(), sink.onScan(), sink.onLog());
  driver.start();
  ASSERT_TRUE(sink.waitFor(20, 8.0));
  driver.stop();
  EXPECT_GE(driver.statistics().connects, 2u);
  std::lock_guard<std::mutex> lock(sink.mutex);
  // The device clock restarted at 0 but stamps keep increasing with host time.
  bool clock_restarted = false;
  for (std::size_t i = 1; i < sink.scans.size(); ++i) {
    EXPECT_GT(sink.scans[i].stamp_s, sink.scans[i - 1].stamp_s);
    clock_restarted = clock_restarted || sink.scans[i].telegram.time_since_startup_us <
                                             sink.scans[i - 1].telegram.time_since_startup_us;
  }
  EXPECT_TRUE(clock_restarted);
}

TEST(Lms111Driver, KeepsTryingWithoutADeviceAndStopsPromptly) {
  Sink sink;
  DriverConfig config;
  config.host = "127.0.0.1";
  config.port = 1;  // nothing listens there
  config.reconnect_min_s = 0.05;
  config.reconnect_max_s = 0.1;
  Lms111Driver driver(config, sink.onScan(), sink.onLog());
  driver.start();
  std::this_thread::sleep_for(std::chrono::milliseconds(400));
  const auto before = std::chrono::steady_clock::now();
  driver.stop();
  EXPECT_LT(Seconds(std::chrono::steady_clock::now() - before).count(), 0.5);
  const DriverStatistics st = driver.statistics();
  EXPECT_GE(st.failures, 3u);
  EXPECT_NE(st.last_error.find("cannot connect to 127.0.0.1:1"), std::string::npos)
      << st.last_error;
  EXPECT_EQ(sink.logs.size(), 1u);  // the same failure is logged once, not per retry
}

TEST(DriverConfig, RejectsWhatTheDeviceCannotDo) {
  DriverConfig c;
  EXPECT_NO_THROW(c.validate());
  EXPECT_EQ(c.beamCount(), 1081);
  c.scan_frequency_hz = 50.0;  // with 0.25 deg
  EXPECT_THROW(c.validate(), Error);
  c = DriverConfig{};
  c.stop_angle_deg = 230.0;
  EXPECT_THROW(c.validate(), Error);
  c = DriverConfig{};
  c.start_angle_deg = 0.1;  // not on the 0.25 deg grid from the stop
  EXPECT_THROW(c.validate(), Error);
  c = DriverConfig{};
  c.port = 0;
  EXPECT_THROW(c.validate(), Error);
}

}  // namespace
}  // namespace lms111
}  // namespace dormant_tree_modeling
