#include <gtest/gtest.h>

#include <fstream>
#include <iterator>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/lms111/cola.h"
#include "dormant_tree_modeling/lms111/cola_fields.h"
#include "dormant_tree_modeling/lms111/scan_telegram.h"

namespace dormant_tree_modeling {
namespace lms111 {
namespace {

std::string realTelegram() {
  std::ifstream in(std::string(DTM_SHARED_DATA_DIR) + "/lms1xx/lms1xx_scan_541pts.txt");
  std::string text((std::istreambuf_iterator<char>(in)), {});
  while (!text.empty() && (text.back() == '\n' || text.back() == '\r'))
    text.pop_back();
  return text;
}

ErrorCode parseCode(const std::string& text) {
  try {
    parseScanTelegram(text);
  } catch (const Error& e) {
    return e.code();
  }
  return ErrorCode::IO_FAILURE;  // "no error" never equals PARSE_ERROR
}

TEST(ColaNumbers, HexSignedDecimalAndTwosComplement) {
  EXPECT_EQ(*parseColaNumber("1388"), 5000);
  EXPECT_EQ(*parseColaNumber("+25"), 25);
  EXPECT_EQ(*parseColaNumber("-450000"), -450000);
  EXPECT_FALSE(parseColaNumber("12G"));
  EXPECT_FALSE(parseColaNumber("+"));
  EXPECT_FALSE(parseColaNumber(""));
  ColaAReader r("FFF92230 3F800000 +7 41200000");
  EXPECT_EQ(r.signedValue("start"), -450000);
  EXPECT_FLOAT_EQ(r.floatValue("scale"), 1.0f);
  EXPECT_EQ(r.signedValue("decimal"), 7);
  EXPECT_FLOAT_EQ(r.floatValue("ten"), 10.0f);
  EXPECT_TRUE(r.atEnd());
}

TEST(ScanTelegram, DecodesTheRealLms1xxTelegram) {
  const ScanTelegram s = parseScanTelegram(realTelegram());
  // The header as decoded by hand, field by field (layout: docs/protocols.md).
  EXPECT_EQ(s.command_type, "sSN");
  EXPECT_EQ(s.version, 1);
  EXPECT_EQ(s.device_number, 1);
  EXPECT_EQ(s.serial_number, 0xA037B9u);
  EXPECT_EQ(s.device_status, 0);
  EXPECT_EQ(s.telegram_counter, 0xC1C3);
  EXPECT_EQ(s.scan_counter, 0xC1C6);
  EXPECT_EQ(s.scan_frequency, 5000u);
  EXPECT_DOUBLE_EQ(s.scanFrequencyHz(), 50.0);
  EXPECT_EQ(s.measurement_frequency, 360u);
  EXPECT_TRUE(s.encoders.empty());
  ASSERT_EQ(s.channels16.size(), 1u);
  const ScanChannel& d = s.channels16[0];
  EXPECT_EQ(d.name, "DIST1");
  EXPECT_FLOAT_EQ(d.scale, 1.0f);
  EXPECT_FLOAT_EQ(d.offset, 0.0f);
  EXPECT_DOUBLE_EQ(d.startAngleDeg(), -45.0);
  EXPECT_DOUBLE_EQ(d.stepDeg(), 0.5);
  ASSERT_EQ(d.values.size(), 541u);
  EXPECT_EQ(d.values.front(), 0x293);
  EXPECT_TRUE(s.channels8.empty());
  EXPECT_FALSE(s.position || s.device_name || s.comment || s.timestamp || s.event);
  EXPECT_EQ(s.channel("DIST1"), &s.channels16[0]);
  EXPECT_EQ(s.channel("RSSI1"), nullptr);
}

TEST(ScanTelegram, EncodeParseRoundTripWithEveryBlock) {
  ScanTelegram s = parseScanTelegram(realTelegram());
  s.encoders = {{0x1234, 7}, {0xFFFFFFFF, 0}};
  ScanChannel rssi = s.channels16[0];
  rssi.name = "RSSI1";
  s.channels16.push_back(rssi);
  ScanChannel eight;
  eight.name = "RSSI2";
  eight.start_angle = -450000;
  eight.angular_step = 2500;
  eight.values = {0, 17, 255};
  s.channels8.push_back(eight);
  s.position = ScanPosition{1.5f, -2.0f, 0.25f, 0.0f, 90.0f, -45.0f, 1};
  s.device_name = "LMS111 front row";  // names may hold spaces
  s.comment = "";
  s.timestamp = ScanTimestamp{2026, 11, 22, 23, 59, 58, 999999};
  s.event = ScanEvent{"FDIN", 42, 123456, -12345};
  const std::string text = encodeScanTelegram(s);
  const ScanTelegram back = parseScanTelegram(text);
  EXPECT_EQ(encodeScanTelegram(back), text);
  ASSERT_EQ(back.encoders.size(), 2u);
  EXPECT_EQ(back.encoders[1].position, 0xFFFFFFFFu);
  ASSERT_EQ(back.channels16.size(), 2u);
  EXPECT_EQ(back.channels16[1].name, "RSSI1");
  ASSERT_EQ(back.channels8.size(), 1u);
  EXPECT_EQ(back.channels8[0].values[2], 255);
  EXPECT_DOUBLE_EQ(back.channels8[0].stepDeg(), 0.25);
  EXPECT_FLOAT_EQ(back.position->rot_y, 90.0f);
  EXPECT_EQ(*back.device_name, "LMS111 front row");
  EXPECT_EQ(*back.comment, "");
  EXPECT_EQ(back.timestamp->microsecond, 999999u);
  EXPECT_EQ(back.event->angle, -12345);
  // The real telegram itself re-encodes to its own text.
  EXPECT_EQ(encodeScanTelegram(parseScanTelegram(realTelegram())), realTelegram());
}

TEST(ScanTelegram, EveryOptionalBlockCombinationRoundTripsInBothProtocols) {
  const ScanTelegram real = parseScanTelegram(realTelegram());
  for (int mask = 0; mask < 32; ++mask) {
    ScanTelegram s = real;
    s.encoders = {{0xDEADBEEF, 300}};
    ScanChannel rssi = s.channels16[0];
    rssi.name = "RSSI1";
    for (auto& v : rssi.values)
      v = static_cast<std::uint16_t>(v & 0xFF);
    s.channels8.push_back(rssi);
    if (mask & 1)
      s.position = ScanPosition{0.5f, 1.0f, 2.0f, 0.0f, 0.0f, 3.14f, 0};
    if (mask & 2)
      s.device_name = "LMS 111";
    if (mask & 4)
      s.comment = "row 7 tree 3";
    if (mask & 8)
      s.timestamp = ScanTimestamp{2026, 3, 4, 5, 6, 7, 890123};
    if (mask & 16)
      s.event = ScanEvent{"FDIN", 1, 2, -3};
    for (const Protocol p : {Protocol::COLA_A, Protocol::COLA_B}) {
      const std::string payload = encodeScanTelegram(s, p);
      const ScanTelegram back = parseScanTelegram(payload, p);
      EXPECT_EQ(encodeScanTelegram(back, p), payload) << "mask " << mask << " " << protocolName(p);
      EXPECT_EQ(back.channels16[0].values, s.channels16[0].values);
      EXPECT_EQ(back.channels8[0].values, rssi.values);
      EXPECT_EQ(back.comment, s.comment);
      EXPECT_EQ(back.device_name, s.device_name);
      EXPECT_EQ(back.event.has_value(), s.event.has_value());
    }
  }
}

TEST(ScanTelegram, ColaBIsBinaryAndChecked) {
  const ScanTelegram real = parseScanTelegram(realTelegram());
  const std::string b = encodeScanTelegram(real, Protocol::COLA_B);
  EXPECT_EQ(b.compare(0, 16, "sSN LMDscandata "), 0);
  // 541 16-bit values dominate: about 2 bytes a beam instead of ~4 characters.
  EXPECT_LT(b.size(), 541u * 2 + 120u);
  EXPECT_THROW(parseScanTelegram(b.substr(0, b.size() - 3), Protocol::COLA_B), Error);
  EXPECT_THROW(parseScanTelegram(b + "x", Protocol::COLA_B), Error);
  ScanTelegram bad = real;
  bad.channels16[0].name = "DIST";  // CoLa-B names are 5 characters
  EXPECT_THROW(encodeScanTelegram(bad, Protocol::COLA_B), Error);
  bad = real;
  bad.digital_inputs[0] = 256;  // 8 bits on the wire
  EXPECT_THROW(encodeScanTelegram(bad, Protocol::COLA_B), Error);
}

TEST(ScanTelegram, JsonOfANameThatIsNotUtf8DoesNotThrow) {
  // Found by the fuzzer (make fuzz): names are the device's bytes, not necessarily UTF-8.
  ScanTelegram s = parseScanTelegram(realTelegram());
  s.device_name = std::string("LMS\xFF\xFE", 5);
  std::string json;
  ASSERT_NO_THROW(json = scanTelegramToJson(s));
  EXPECT_NE(json.find("device_name"), std::string::npos);
}

TEST(ScanTelegram, InconsistentTelegramsAreRejectedWithAReason) {
  const std::string real = realTelegram();
  EXPECT_EQ(parseCode(""), ErrorCode::PARSE_ERROR);
  EXPECT_EQ(parseCode("sRA STlms 7"), ErrorCode::PARSE_ERROR);
  EXPECT_EQ(parseCode(real.substr(0, real.size() / 2)), ErrorCode::PARSE_ERROR);  // cut short
  EXPECT_EQ(parseCode(real + " 0"), ErrorCode::PARSE_ERROR);                      // left over
  std::string bad_hex = real;
  bad_hex.replace(bad_hex.find(" 293 "), 5, " 2Z3 ");
  EXPECT_EQ(parseCode(bad_hex), ErrorCode::PARSE_ERROR);
  std::string wrong_count = real;
  wrong_count.replace(wrong_count.find(" 21D "), 5, " 21E ");  // one value more than sent
  EXPECT_EQ(parseCode(wrong_count), ErrorCode::PARSE_ERROR);
  std::string huge_count = real;
  huge_count.replace(huge_count.find(" 21D "), 5, " FFFF ");
  EXPECT_EQ(parseCode(huge_count), ErrorCode::PARSE_ERROR);
  std::string bad_flag = real;
  bad_flag.replace(bad_flag.size() - 1, 1, "2");
  EXPECT_EQ(parseCode(bad_flag), ErrorCode::PARSE_ERROR);
  try {
    parseScanTelegram(bad_hex);
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("DIST1"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("2Z3"), std::string::npos) << e.what();
  }
}

TEST(ColaAFramer, SplitCoalescedGarbageAndOverlong) {
  ColaAFramer f(100);
  f.feed("noise");
  f.feed(frameColaA("sRA STlms 7").substr(0, 5));
  EXPECT_FALSE(f.next());
  f.feed(frameColaA("sRA STlms 7").substr(5) + frameColaA("sAN Run 1") + "junk");
  EXPECT_EQ(*f.next(), "sRA STlms 7");
  EXPECT_EQ(*f.next(), "sAN Run 1");
  EXPECT_FALSE(f.next());
  EXPECT_EQ(f.skippedBytes(), 9u);  // "noise" and "junk"
  // A telegram cut short by a new STX is dropped, the new one kept.
  f.feed(std::string(1, STX) + "sSN LMDsc" + frameColaA("sEA LMDscandata 1"));
  EXPECT_EQ(*f.next(), "sEA LMDscandata 1");
  EXPECT_EQ(f.droppedTelegrams(), 1u);
  // Over the bound: dropped, the buffer stays bounded, the stream recovers.
  f.feed(std::string(1, STX) + std::string(500, 'A'));
  EXPECT_FALSE(f.next());
  EXPECT_LE(f.buffered(), 100u);
  f.feed(std::string(1, ETX) + frameColaA("sRA STlms 6"));
  EXPECT_EQ(*f.next(), "sRA STlms 6");
}

TEST(ColaBFramer, ChecksumLengthAndResynchronisation) {
  ColaBFramer f(1000);
  const std::string a = frameColaB("sRA STlms \x07"), b = frameColaB("sAN Run \x01");
  std::string corrupt = frameColaB("sAN Run \x01");
  corrupt[10] ^= 0x20;  // a payload byte: the checksum no longer matches
  f.feed("\x01\x02junk");
  f.feed(a.substr(0, 6));
  EXPECT_FALSE(f.next());
  f.feed(a.substr(6) + corrupt + b);
  EXPECT_EQ(*f.next(), "sRA STlms \x07");
  EXPECT_EQ(*f.next(), "sAN Run \x01");
  EXPECT_FALSE(f.next());
  EXPECT_EQ(f.badChecksums(), 1u);
  std::string huge = "\x02\x02\x02\x02";
  huge += std::string("\x7F\x00\x00\x00", 4);
  f.feed(huge + b);
  EXPECT_EQ(*f.next(), "sAN Run \x01");
  EXPECT_EQ(f.droppedFrames(), 1u);
}

TEST(DeviceMessages, SfaCodesAndStatesAreReadable) {
  EXPECT_NE(describeSfaError(1).find("access denied"), std::string::npos);
  EXPECT_NE(describeSfaError(4).find("local condition"), std::string::npos);
  EXPECT_NE(describeSfaError(99).find("99"), std::string::npos);
  EXPECT_EQ(deviceStateName(7), "ready for measurement");
  EXPECT_NE(deviceStateName(12).find("12"), std::string::npos);
}

TEST(DeviceMessages, DeviceBytesInAnErrorAreEscapedNotWrittenRaw) {
  try {
    parseScanTelegram("sSN LMDscandata 1 1 \x1b[2J\n 0");
    FAIL();
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_EQ(m.find('\x1b'), std::string::npos) << "a raw escape byte reached the message";
    EXPECT_EQ(m.find('\n'), std::string::npos);
    EXPECT_NE(m.find("\\x1B[2J\\x0A"), std::string::npos) << m;
  }
  EXPECT_EQ(printableBytes(std::string("a\0b\\", 4)), "a\\x00b\\x5C");
  EXPECT_EQ(printableBytes(std::string(200, 'x'), 3), "xxx...");
}

}  // namespace
}  // namespace lms111
}  // namespace dormant_tree_modeling
