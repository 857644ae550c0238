// The emulated device's command interpreter, the clock mapping and the LaserScan conversion.
#include <gtest/gtest.h>

#include <cmath>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/random.h"
#include "dormant_tree_modeling/emulation/lms111_emulator.h"
#include "dormant_tree_modeling/lms111/clock_mapper.h"
#include "dormant_tree_modeling/lms111/cola_fields.h"
#include "dormant_tree_modeling/lms111/laser_scan.h"

namespace dormant_tree_modeling {
namespace lms111 {
namespace {

using namespace emulation;  // the tests run the driver against the device emulators

std::shared_ptr<ScanSource> recorded() {
  return std::make_shared<RecordedScanSource>(RecordedScanSource::fromFile(
      std::string(DTM_SHARED_DATA_DIR) + "/lms1xx/lms1xx_scan_541pts.txt"));
}

// Sends one command (words and arguments as CoLa-A text) and returns the reply as CoLa-A text.
class DeviceFixture : public ::testing::Test {
 protected:
  DeviceFixture() : device_(config(), recorded()) {}
  static LmsEmulatorConfig config() {
    LmsEmulatorConfig c;
    c.spin_up_seconds = 1.0;
    return c;
  }
  std::string ask(const std::string& command, double now = 10.0) {
    const auto replies = device_.handle(command, session_, now);
    return replies.empty() ? std::string() : replies.front();
  }
  EmulatedLms111 device_;
  LmsSession session_;
};

TEST_F(DeviceFixture, ConfigurationNeedsTheAuthorisedClientLevel) {
  EXPECT_EQ(ask("sMN mLMPsetscancfg 1388 1 1388 FFF92230 225510"), "sFA 1");
  EXPECT_EQ(ask("sMN SetAccessMode 3 12345678"), "sAN SetAccessMode 0");  // wrong password
  EXPECT_EQ(ask("sMN SetAccessMode 3 F4724744"), "sAN SetAccessMode 1");
  EXPECT_EQ(ask("sMN mLMPsetscancfg 1388 1 1388 FFF92230 225510"),
            "sAN mLMPsetscancfg 0 1388 1 1388 FFF92230 225510");
  // 50 Hz with 0.25 deg is not a pair the LMS111 runs.
  EXPECT_EQ(ask("sMN mLMPsetscancfg 1388 1 9C4 FFF92230 225510").substr(0, 20),
            "sAN mLMPsetscancfg 2");
  EXPECT_EQ(ask("sMN mLMPsetscancfg 7D0 1 1388 FFF92230 225510").substr(0, 20),
            "sAN mLMPsetscancfg 1");
  // Applied by Run, which also logs out.
  EXPECT_EQ(ask("sRN LMPscancfg"), "sRA LMPscancfg 9C4 1 9C4 FFF92230 225510");
  EXPECT_EQ(ask("sMN Run"), "sAN Run 1");
  EXPECT_EQ(ask("sRN LMPscancfg"), "sRA LMPscancfg 1388 1 1388 FFF92230 225510");
  EXPECT_EQ(ask("sWN LMPoutputRange 1 1388 0 F4240"), "sFA 1");
}

TEST_F(DeviceFixture, UnknownCommandsMissingArgumentsAndWrongStateAnswerSfa) {
  EXPECT_EQ(ask("sMN NoSuchMethod"), "sFA 2");
  EXPECT_EQ(ask("sRN NoSuchVariable"), "sFA 3");
  EXPECT_EQ(ask("xyz"), "sFA B");
  ask("sMN SetAccessMode 3 F4724744");
  EXPECT_EQ(ask("sMN mLMPsetscancfg 1388"), "sFA 8");       // too few parameters
  EXPECT_EQ(ask("sWN LMPoutputRange 1 9C4 0 1"), "sFA 5");  // not on the beam grid
  EXPECT_EQ(ask("sMN LMCstopmeas"), "sAN LMCstopmeas 0");
  EXPECT_EQ(ask("sRN STlms").substr(0, 11), "sRA STlms 3");  // idle
  EXPECT_EQ(ask("sRN LMDscandata"), "sFA 4");                // not measuring
  EXPECT_EQ(ask("sMN LMCstartmeas", 20.0), "sAN LMCstartmeas 0");
  EXPECT_EQ(ask("sRN STlms", 20.5).substr(0, 11), "sRA STlms 5");  // spinning up
  EXPECT_EQ(ask("sRN STlms", 21.5).substr(0, 11), "sRA STlms 7");
  EXPECT_EQ(ask("sRN LMDscandata", 21.5).substr(0, 15), "sRA LMDscandata");
}

TEST_F(DeviceFixture, ScansFollowTheConfigurationAndCountersAdvance) {
  ask("sMN SetAccessMode 3 F4724744");
  EXPECT_EQ(ask("sWN LMDscandatacfg 01 00 1 0 0 00 00 0 1 0 1 +1"), "sWA LMDscandatacfg");
  ask("sMN Run");
  const auto a = device_.nextScan(12.0), b = device_.nextScan(12.04);
  ASSERT_TRUE(a && b);
  EXPECT_EQ(static_cast<std::uint16_t>(b->scan_counter - a->scan_counter), 1);
  EXPECT_EQ(b->time_since_startup_us - a->time_since_startup_us, 40000u);
  ASSERT_EQ(a->channels16.size(), 1u);  // DIST1
  ASSERT_EQ(a->channels8.size(), 1u);   // RSSI1 as the 8-bit values that were asked for
  EXPECT_EQ(a->channels16[0].values.size(), 1081u);
  EXPECT_EQ(a->channels16[0].angular_step, 2500);
  EXPECT_EQ(a->measurement_frequency, 360u);  // 36 kHz rays over the full turn
  EXPECT_TRUE(a->device_name && a->timestamp && !a->comment);
  // The recorded 0.5 deg scan fills the 0.25 deg grid by nearest angle: beam 0 is its first.
  EXPECT_EQ(a->channels16[0].values[0], 0x293);
}

TEST_F(DeviceFixture, ColaBRepliesAndInjectedSfa) {
  LmsFaults faults;
  faults.addSfa("mLMPsetscancfg:4:1");
  EXPECT_THROW(faults.addSfa("mLMPsetscancfg"), Error);
  EXPECT_THROW(faults.addSfa("Run:x"), Error);
  EmulatedLms111 device(config(), recorded(), faults);
  LmsSession b;
  b.protocol = Protocol::COLA_B;
  auto ask_b = [&](const std::function<void(FieldWriter&)>& write) {
    ColaBWriter w;
    write(w);
    const auto replies = device.handle(w.payload(), b, 10.0);
    EXPECT_EQ(replies.size(), 1u);
    return ColaBReader(replies.at(0));
  };
  auto login = ask_b([](FieldWriter& w) {
    w.word("sMN");
    w.word("SetAccessMode");
    w.unsignedValue(3, 8);
    w.unsignedValue(AUTHORISED_CLIENT_PASSWORD);
  });
  EXPECT_EQ(login.word("type"), "sAN");
  EXPECT_EQ(login.word("name"), "SetAccessMode");
  EXPECT_EQ(login.unsignedValue("result", 8), 1u);
  auto set = [](FieldWriter& w) {
    w.word("sMN");
    w.word("mLMPsetscancfg");
    w.unsignedValue(5000);
    w.unsignedValue(1, 16);
    w.unsignedValue(5000);
    w.signedValue(-450000);
    w.signedValue(2250000);
  };
  ColaBWriter set_request;
  set(set_request);
  const auto first = device.handle(set_request.payload(), b, 10.0);
  ASSERT_EQ(first.size(), 1u);
  EXPECT_EQ(first[0], std::string("sFA\x00\x04", 5));  // the code right after "sFA"
  EXPECT_EQ(sfaCode(Protocol::COLA_B, first[0]), 4);
  auto second = ask_b(set);
  EXPECT_EQ(second.word("type"), "sAN");
}

TEST(SfaCode, ReadsBothProtocolsAndTheSpacedCoLaBForm) {
  EXPECT_EQ(sfaCode(Protocol::COLA_A, "sFA 5"), 5);
  EXPECT_EQ(sfaCode(Protocol::COLA_A, "sFA B"), 11);
  EXPECT_EQ(sfaCode(Protocol::COLA_B, std::string("sFA\x00\x05", 5)), 5);
  EXPECT_EQ(sfaCode(Protocol::COLA_B, std::string("sFA \x00\x05", 6)), 5);
  EXPECT_EQ(sfaCode(Protocol::COLA_B, std::string("sFA\x05", 4)), 5);
  EXPECT_FALSE(sfaCode(Protocol::COLA_A, "sAN Run 1"));
  EXPECT_FALSE(sfaCode(Protocol::COLA_A, "sFA x"));
  EXPECT_EQ(sfaReply(Protocol::COLA_A, 11), "sFA B");
  EXPECT_EQ(sfaReply(Protocol::COLA_B, 0x0102), std::string("sFA\x01\x02", 5));
}

TEST(LaserScan, RosAnglesRep117AndIntensities) {
  ScanTelegram s;
  s.scan_frequency = 2500;
  s.measurement_frequency = 360;
  ScanChannel d;
  d.name = "DIST1";
  d.start_angle = -450000;
  d.angular_step = 2500;
  d.values = {0, 300, 1500, 25000, 3};
  s.channels16.push_back(d);
  ScanChannel r = d;
  r.name = "RSSI1";
  r.values = {0, 10, 200, 5, 0};
  s.channels16.push_back(r);
  const LaserScanData l = toLaserScan(s, 0.5, 20.0);
  EXPECT_NEAR(l.angle_min, -135.0 * M_PI / 180.0, 1e-12);
  EXPECT_NEAR(l.angle_increment, 0.25 * M_PI / 180.0, 1e-12);
  EXPECT_NEAR(l.angle_max, l.angle_min + 4 * l.angle_increment, 1e-12);
  EXPECT_NEAR(l.time_increment, 1.0 / 36000.0, 1e-12);
  EXPECT_NEAR(l.scan_time, 0.04, 1e-12);
  EXPECT_TRUE(std::isinf(l.ranges[0]) && l.ranges[0] > 0);  // no echo
  EXPECT_TRUE(std::isinf(l.ranges[1]) && l.ranges[1] < 0);  // too close
  EXPECT_FLOAT_EQ(l.ranges[2], 1.5f);
  EXPECT_TRUE(std::isinf(l.ranges[3]) && l.ranges[3] > 0);  // beyond range_max
  EXPECT_TRUE(std::isnan(l.ranges[4]));  // the device's code for an invalid measurement
  EXPECT_EQ(l.intensities, (std::vector<float>{0, 10, 200, 5, 0}));
  s.channels16[1].values.pop_back();
  EXPECT_THROW(toLaserScan(s, 0.5, 20.0), Error);
  s.channels16.clear();
  EXPECT_THROW(toLaserScan(s, 0.5, 20.0), Error);
}

TEST(ClockMapper, FollowsDriftThroughJitterAndWrap) {
  // Device 80 ppm fast, starting 3 s before its clock wraps; reception delays of 1-3 ms with
  // every 20th telegram held up by 40 ms.
  ClockMapper mapper;
  Rng rng(5);
  const double host0 = 1.7e9, drift = 80e-6;
  const std::uint32_t start_us = 0xFFFFFFFFu - 3000000u;
  double worst = 0.0;
  for (int k = 0; k < 25 * 40; ++k) {
    const double host_true = host0 + k * 0.04;  // the first ray, in host time
    const auto device = [&](double host) {
      return static_cast<std::uint32_t>(
          start_us + static_cast<std::uint64_t>((host - host0) * (1 + drift) * 1e6));
    };
    const double sent = host_true + 0.03;
    const double delay = 0.001 + 0.002 * rng.uniform() + (k % 20 == 7 ? 0.04 : 0.0);
    EXPECT_FALSE(mapper.observe(device(sent), sent + delay));
    const double stamp = *mapper.toHost(device(host_true));
    if (k >= 25 * 5)  // after 5 s of history
      worst = std::max(worst, std::abs(stamp - host_true));
  }
  // The lower envelope sits on the smallest delay (~1 ms); jitter and spikes are gone.
  EXPECT_LT(worst, 0.0015);
  EXPECT_NEAR(mapper.drift(), -drift, 20e-6);
  // A device clock that restarts from zero resets the mapping.
  EXPECT_TRUE(mapper.observe(1000, host0 + 41.0));
  EXPECT_EQ(mapper.samples(), 1u);
}

}  // namespace
}  // namespace lms111
}  // namespace dormant_tree_modeling
