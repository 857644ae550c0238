// The LMS1xx protocol against bytes recorded from real devices: a whole LMS511 session in
// CoLa-B (../shared/data/lms1xx/lms511_session_colab.txt) and one LMS1xx scan in CoLa-A. Our
// requests must be the recorded ones byte for byte, our encoder must reproduce the recorded
// scans, the emulator must refuse the layouts real devices refuse, and the driver must stream
// from a device that replays the real session.
#include <gtest/gtest.h>

#include <chrono>
#include <condition_variable>
#include <mutex>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/emulation/lms111_server.h"
#include "dormant_tree_modeling/emulation/session_replay.h"
#include "dormant_tree_modeling/lms111/capture.h"
#include "dormant_tree_modeling/lms111/driver.h"
#include "dormant_tree_modeling/lms111/requests.h"

namespace dormant_tree_modeling {
namespace lms111 {
namespace {

using namespace emulation;  // the tests run the driver against the device emulators

std::string sessionPath() {
  return std::string(DTM_SHARED_DATA_DIR) + "/lms1xx/lms511_session_colab.txt";
}

const std::vector<CapturedTelegram>& realSession() {
  static const std::vector<CapturedTelegram> session = readSessionFile(sessionPath());
  return session;
}

// The first recorded payload that starts with `prefix` ("sWN LMDscandatacfg ").
std::string recorded(const std::string& prefix) {
  for (const auto& t : realSession()) {
    if (t.payload.compare(0, prefix.size(), prefix) == 0)
      return t.payload;
  }
  ADD_FAILURE() << "the session holds no " << prefix;
  return {};
}

std::vector<const CapturedTelegram*> recordedScans() {
  std::vector<const CapturedTelegram*> scans;
  for (const auto& t : realSession()) {
    if (t.payload.compare(0, 16, "sSN LMDscandata ") == 0)
      scans.push_back(&t);
  }
  return scans;
}

TEST(RealSession, CutsIntoWholeTelegramsWithTheirTimes) {
  const auto& session = realSession();
  ASSERT_EQ(session.size(), 123u);  // one frame a line
  for (const auto& t : session)
    EXPECT_TRUE(t.error.empty()) << "offset " << t.offset << ": " << t.error;
  EXPECT_EQ(recordedScans().size(), 20u);
  EXPECT_DOUBLE_EQ(session.front().time_s, 0.202789);
  EXPECT_EQ(session.front().payload, std::string("sMN SetAccessMode \x03\xF4\x72\x47\x44", 23));
}

TEST(RealSession, RecordedScansDecodeAndOurEncoderReproducesTheirBytes) {
  const auto scans = recordedScans();
  ASSERT_FALSE(scans.empty());
  std::uint16_t last_counter = 0;
  for (const CapturedTelegram* t : scans) {
    const ScanTelegram s = parseScanTelegram(t->payload, Protocol::COLA_B);
    EXPECT_EQ(s.scan_frequency, 2500u);
    const ScanChannel* dist = s.channel("DIST1");
    ASSERT_NE(dist, nullptr);
    EXPECT_EQ(dist->values.size(), 1141u);
    EXPECT_EQ(dist->start_angle, -50000);
    EXPECT_EQ(dist->angular_step, 1667);
    ASSERT_EQ(s.channels8.size(), 1u);  // the LMS511 sends its RSSI1 as 8-bit values
    EXPECT_EQ(s.channels8[0].name, "RSSI1");
    EXPECT_TRUE(s.timestamp.has_value());
    if (t != scans.front()) {
      EXPECT_EQ(static_cast<std::uint16_t>(s.scan_counter - last_counter), 1);
    }
    last_counter = s.scan_counter;
    EXPECT_EQ(encodeScanTelegram(s, Protocol::COLA_B), t->payload) << "offset " << t->offset;
  }
}

TEST(Requests, AreTheRecordedHostsRequestsByteForByte) {
  const Protocol b = Protocol::COLA_B;
  EXPECT_EQ(loginRequest(b), recorded("sMN SetAccessMode "));
  EXPECT_EQ(plainRequest(b, "sMN", "LMCstartmeas"), recorded("sMN LMCstartmeas"));
  EXPECT_EQ(plainRequest(b, "sMN", "Run"), recorded("sMN Run"));
  EXPECT_EQ(streamRequest(b, true), recorded("sEN LMDscandata "));
  ScanArea area;  // what the recorded LMS511 host wrote: 1/6 deg from -5 to 185 deg
  area.resolution = 1667;
  area.start_angle = -50000;
  area.stop_angle = 1850000;
  EXPECT_EQ(outputRangeRequest(b, area), recorded("sWN LMPoutputRange "));
  ScanDataOutput output;  // the recorded host asked for RSSI and the time block
  output.rssi = true;
  output.time_block = true;
  const std::string ours = scanDataConfigRequest(b, output);
  EXPECT_EQ(ours, recorded("sWN LMDscandatacfg "));
  EXPECT_EQ(ours.size() - std::string("sWN LMDscandatacfg ").size(), 13u);
}

TEST(Requests, ScanDataConfigInCoLaAIsTheDocumentedTwelveFields) {
  ScanDataOutput output;
  output.rssi = true;
  output.rssi_16bit = true;
  const std::string ours = scanDataConfigRequest(Protocol::COLA_A, output);
  // SICK's listing and both public LMS1xx drivers: "01 00 1 1 0 00 00 0 0 0 0 +1".
  const std::vector<std::string> documented = {"01", "00", "1", "1", "0", "00",
                                               "00", "0",  "0", "0", "0", "+1"};
  ColaAReader reader(ours);
  EXPECT_EQ(reader.token("type"), "sWN");
  EXPECT_EQ(reader.token("name"), "LMDscandatacfg");
  for (const auto& expected : documented) {
    const std::string token = reader.token("field");
    EXPECT_EQ(parseColaNumber(token), parseColaNumber(expected)) << token << " vs " << expected;
  }
  EXPECT_TRUE(reader.atEnd()) << ours;
}

std::string ask(EmulatedLms111& device, LmsSession& session, const std::string& payload) {
  return device.handle(payload, session, 1.0).back();
}

TEST(EmulatedLms111, RefusesTheOldScanDataConfigLayoutsAsTheDeviceDoes) {
  auto device = makeSessionReplay(realSession());
  auto plain = std::make_shared<EmulatedLms111>(
      LmsEmulatorConfig{}, std::make_shared<RecordedScanSource>(parseScanTelegram(
                               recordedScans().front()->payload, Protocol::COLA_B)));
  for (EmulatedLms111* d : {device.get(), plain.get()}) {
    LmsSession a, b;
    a.protocol = Protocol::COLA_A;
    b.protocol = Protocol::COLA_B;
    for (LmsSession* s : {&a, &b})
      ASSERT_EQ(ask(*d, *s, loginRequest(s->protocol)).substr(0, 17), "sAN SetAccessMode");
    // The channel as one 16-bit value and the encoder as one value: 10 fields in CoLa-A.
    EXPECT_EQ(ask(*d, a, "sWN LMDscandatacfg 1 1 0 0 0 0 0 0 0 1").substr(0, 3), "sFA");
    // The channel as one 16-bit value in CoLa-B: 00 01 where the device reads mask, reserved.
    const std::string old_b(
        "sWN LMDscandatacfg \x00\x01\x01\x00\x00\x00\x00\x00\x00\x00\x00\x00\x01", 32);
    EXPECT_EQ(ask(*d, b, old_b).substr(0, 3), "sFA");
    // The recorded request and the documented form are taken.
    EXPECT_EQ(ask(*d, b, recorded("sWN LMDscandatacfg ")), "sWA LMDscandatacfg ");
    EXPECT_EQ(ask(*d, a, "sWN LMDscandatacfg 01 00 1 1 0 00 00 0 0 0 0 +1"), "sWA LMDscandatacfg");
    EXPECT_TRUE(d->outputConfig().rssi);
    // One field too many or too few.
    EXPECT_EQ(ask(*d, a, "sWN LMDscandatacfg 01 00 1 1 0 00 00 0 0 0 0 +1 0"), "sFA 7");
    EXPECT_EQ(ask(*d, a, "sWN LMDscandatacfg 01 00 1 1 0 00 00 0 0 0 0"), "sFA 8");
  }
}

TEST(SessionReplay, AnswersWhatTheRecordedHostAskedWithTheRecordedReplies) {
  auto device = makeSessionReplay(realSession());
  LmsSession s;
  s.protocol = Protocol::COLA_B;
  const auto replies = device->handle(recorded("sMN SetAccessMode "), s, 1.0);
  ASSERT_EQ(replies.size(), 2u);
  EXPECT_EQ(replies[0].compare(0, 4, "sSN "), 0) << "a recorded event comes first";
  EXPECT_EQ(replies[1], recorded("sAN SetAccessMode "));
  EXPECT_EQ(ask(*device, s, recorded("sMN LMCstartmeas")), recorded("sAN LMCstartmeas "));
  EXPECT_EQ(ask(*device, s, recorded("sMN Run")), recorded("sAN Run "));
  // A recorded command of another size than the recorded request: buffer under- or overflow.
  ask(*device, s, loginRequest(Protocol::COLA_B));
  const std::string short_cfg = recorded("sWN LMDscandatacfg ").substr(0, 31);
  EXPECT_EQ(ask(*device, s, short_cfg), std::string("sFA\x00\x08", 5));
  EXPECT_EQ(ask(*device, s, recorded("sWN LMDscandatacfg ") + '\0'), std::string("sFA\x00\x07", 5));
  // What the recording lacks is answered in the device's layout.
  EXPECT_EQ(ask(*device, s, plainRequest(Protocol::COLA_B, "sRN", "DeviceIdent")).substr(0, 15),
            "sRA DeviceIdent");
}

// Collects the driver's scans.
struct Sink {
  std::mutex mutex;
  std::condition_variable changed;
  std::vector<StampedScan> scans;
  bool waitFor(std::size_t n, double timeout_s) {
    std::unique_lock<std::mutex> lock(mutex);
    return changed.wait_for(lock, std::chrono::duration<double>(timeout_s),
                            [&] { return scans.size() >= n; });
  }
  Lms111Driver::ScanCallback onScan() {
    return [this](const StampedScan& s) {
      std::lock_guard<std::mutex> lock(mutex);
      scans.push_back(s);
      changed.notify_all();
    };
  }
};

DriverStatistics streamFrom(std::shared_ptr<EmulatedLms111> device, Protocol protocol, Sink& sink) {
  LmsServerConfig options;
  options.cola_a_port = options.cola_b_port = 0;
  LmsServer server(device, options);
  DriverConfig config;
  config.host = "127.0.0.1";
  config.protocol = protocol;
  config.port = protocol == Protocol::COLA_A ? server.colaAPort() : server.colaBPort();
  config.scan_frequency_hz = 50.0;
  config.angular_resolution_deg = 0.5;
  config.reply_timeout_s = 1.0;
  Lms111Driver driver(config, sink.onScan());
  driver.start();
  EXPECT_TRUE(sink.waitFor(25, 10.0)) << protocolName(protocol);
  driver.stop();
  return driver.statistics();
}

TEST(SessionReplay, TheDriverStreams541BeamsAt50HzFromTheRealSessionInCoLaB) {
  LmsEmulatorConfig config;
  config.spin_up_seconds = 0.05;
  config.reported_angle_error = 3;  // as a real LMS111 reports its range
  Sink sink;
  const DriverStatistics st =
      streamFrom(makeSessionReplay(realSession(), config), Protocol::COLA_B, sink);
  EXPECT_EQ(st.failures, 0u) << st.last_error;
  EXPECT_EQ(st.parse_errors, 0u);
  EXPECT_GT(st.events, 0u) << "the recorded events were interleaved";
  std::lock_guard<std::mutex> lock(sink.mutex);
  const ScanTelegram first = parseScanTelegram(recordedScans().front()->payload, Protocol::COLA_B);
  for (std::size_t i = 0; i < sink.scans.size(); ++i) {
    const ScanTelegram& t = sink.scans[i].telegram;
    EXPECT_EQ(t.scan_frequency, 5000u);
    ASSERT_NE(t.channel("DIST1"), nullptr);
    EXPECT_EQ(t.channel("DIST1")->values.size(), 541u);
    EXPECT_EQ(t.serial_number, first.serial_number);
    if (i > 0) {
      EXPECT_EQ(
          static_cast<std::uint16_t>(t.scan_counter - sink.scans[i - 1].telegram.scan_counter), 1);
    }
  }
  // Beam 90 (0 deg) is the recorded LMS511 beam at 0 deg: its 31st (-5 + 30/6 deg).
  EXPECT_EQ(sink.scans.front().telegram.channel("DIST1")->values[90],
            first.channel("DIST1")->values[30]);
}

TEST(SessionReplay, TheDriverStreamsTheRecordedCoLaATelegramInCoLaA) {
  const auto recorded_scan = parseScanTelegram(
      readTelegramFile(std::string(DTM_SHARED_DATA_DIR) + "/lms1xx/lms1xx_scan_541pts.txt"));
  LmsEmulatorConfig config;
  config.spin_up_seconds = 0.05;
  config.reported_angle_error = 3;
  Sink sink;
  const DriverStatistics st = streamFrom(
      std::make_shared<EmulatedLms111>(config, std::make_shared<RecordedScanSource>(recorded_scan)),
      Protocol::COLA_A, sink);
  EXPECT_EQ(st.failures, 0u) << st.last_error;
  std::lock_guard<std::mutex> lock(sink.mutex);
  ASSERT_FALSE(sink.scans.empty());
  EXPECT_EQ(sink.scans.back().telegram.channel("DIST1")->values,
            recorded_scan.channel("DIST1")->values);
  EXPECT_EQ(sink.scans.back().telegram.scan_frequency, 5000u);
}

TEST(Capture, ReportsBadChecksumsAndCutOffFramesWithTheirOffsetsAndGoesOn) {
  const std::string good = frameColaB("sRA STlms \x07");
  std::string bad = frameColaB("sRA STlms \x06");
  bad.back() ^= 0x01;
  const std::string stream = "junk" + good + bad + good + good.substr(0, 10);
  const auto cut = cutColaBStream(stream);
  ASSERT_EQ(cut.size(), 4u);
  EXPECT_EQ(cut[0].offset, 4u);
  EXPECT_EQ(cut[0].payload, "sRA STlms \x07");
  EXPECT_EQ(cut[1].offset, 4u + good.size());
  EXPECT_EQ(cut[1].error, "bad checksum");
  EXPECT_EQ(cut[2].payload, "sRA STlms \x07");
  EXPECT_EQ(cut[3].offset, 4u + 2 * good.size() + bad.size());
  EXPECT_NE(cut[3].error.find("cut-off"), std::string::npos);
  const auto a = cutColaAStream("x\x02sAN Run 1\x03\x02sRA STl\x02sEA LMDscandata 1\x03\x02sSN");
  ASSERT_EQ(a.size(), 4u);
  EXPECT_EQ(a[0].payload, "sAN Run 1");
  EXPECT_NE(a[1].error.find("cut-off"), std::string::npos);
  EXPECT_EQ(a[2].payload, "sEA LMDscandata 1");
  EXPECT_NE(a[3].error.find("cut-off"), std::string::npos);
}

TEST(Capture, AFloodOfFrameStartsIsOneFindingAndLinearToCut) {
  // 2 MB of STX or magic bytes: one folded finding each (quadratic cutting took minutes).
  const std::string flood(2u << 20, '\x02');
  const auto a = cutColaAStream(flood);
  ASSERT_EQ(a.size(), 1u);
  EXPECT_EQ(a[0].failures, flood.size());
  EXPECT_EQ(a[0].last_offset, flood.size() - 1);
  const auto b = cutColaBStream(flood + frameColaB("sAN Run \x01"));
  ASSERT_EQ(b.size(), 2u);
  EXPECT_FALSE(b[0].error.empty());
  EXPECT_EQ(b[1].payload, "sAN Run \x01") << "the frame after the flood";
  for (const Protocol p : {Protocol::COLA_A, Protocol::COLA_B}) {
    auto framer = makeFramer(p);
    framer->feed(flood);
    framer->feed(frame(p, "sAN Run 1"));
    const auto got = framer->next();
    ASSERT_TRUE(got.has_value()) << protocolName(p);
    EXPECT_EQ(*got, "sAN Run 1");
    EXPECT_GE(framer->discarded(), 1u);
  }
}

TEST(Capture, ASessionLineThatIsNotSecondsAndHexIsAParseErrorNamingTheLine) {
  try {
    readSessionText("# comment\n0.1 0202020200000003734142\n0.2 zz\n");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::PARSE_ERROR);
    EXPECT_NE(std::string(e.what()).find("line 3"), std::string::npos) << e.what();
  }
  EXPECT_THROW(readSessionFile("/nonexistent/session.txt"), Error);
  EXPECT_THROW(readSessionFile(DTM_SHARED_DATA_DIR), Error);  // a directory
}

}  // namespace
}  // namespace lms111
}  // namespace dormant_tree_modeling
