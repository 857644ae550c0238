#include <gtest/gtest.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <unistd.h>

#include <cmath>
#include <fstream>
#include <functional>
#include <limits>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/io/point_cloud_io.h"
#include "temp_dir.h"

namespace dormant_tree_modeling {
namespace {

using io::CloudFormat;
using io::readCloud;
using io::writeCloud;

Cloud smallCloud() {
  Cloud c;
  c.push_back(pcl::PointXYZ(0.0f, 0.0f, 0.0f));
  c.push_back(pcl::PointXYZ(1.25f, -2.5f, 3.75f));
  c.push_back(pcl::PointXYZ(-0.125f, 0.5f, 10.0f));
  return c;
}

void expectSameCloud(const Cloud& a, const Cloud& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_FLOAT_EQ(a[i].x, b[i].x) << "point " << i;
    EXPECT_FLOAT_EQ(a[i].y, b[i].y) << "point " << i;
    EXPECT_FLOAT_EQ(a[i].z, b[i].z) << "point " << i;
  }
}

ErrorCode errorOf(const std::function<void()>& fn) {
  try {
    fn();
  } catch (const Error& e) {
    return e.code();
  }
  ADD_FAILURE() << "no Error thrown";
  return ErrorCode::INVALID_ARGUMENT;
}

TEST(CloudFormat, FromExtensionIsCaseInsensitive) {
  EXPECT_EQ(io::cloudFormatFromPath("a/b.PCD"), CloudFormat::PCD);
  EXPECT_EQ(io::cloudFormatFromPath("tree.ply"), CloudFormat::PLY);
  EXPECT_EQ(io::cloudFormatFromPath("tree.xyz"), CloudFormat::XYZ);
  EXPECT_EQ(io::cloudFormatFromPath("tree.txt"), CloudFormat::XYZ);
  EXPECT_EQ(errorOf([] { io::cloudFormatFromPath("tree.las"); }), ErrorCode::UNKNOWN_FORMAT);
  EXPECT_EQ(errorOf([] { io::cloudFormatFromPath("tree"); }), ErrorCode::UNKNOWN_FORMAT);
}

class RoundTrip : public ::testing::TestWithParam<const char*> {};

TEST_P(RoundTrip, WriteThenReadGivesSamePoints) {
  test::TempDir dir;
  const std::string path = dir.file(std::string("cloud.") + GetParam());
  writeCloud(path, smallCloud());
  const auto result = readCloud(path);
  expectSameCloud(*result.cloud, smallCloud());
  EXPECT_EQ(result.points_in_file, 3u);
  EXPECT_EQ(result.dropped_non_finite, 0u);
  EXPECT_TRUE(result.offset.isZero());
}

INSTANTIATE_TEST_SUITE_P(Formats, RoundTrip, ::testing::Values("pcd", "ply", "xyz"));

TEST(ReadXyz, IgnoresExtraColumnsCommentsBlankLinesAndHeader) {
  test::TempDir dir;
  const auto path = dir.write("t.txt",
                              "x y z intensity\n"
                              "# comment\n"
                              "\n"
                              "1 2 3 99 7\n"
                              "4.5,5.5,6.5\n"
                              "  -1e-3\t+2 3.0e1 \r\n");
  const auto r = readCloud(path);
  ASSERT_EQ(r.cloud->size(), 3u);
  EXPECT_FLOAT_EQ((*r.cloud)[0].x, 1.0f);
  EXPECT_FLOAT_EQ((*r.cloud)[1].y, 5.5f);
  EXPECT_FLOAT_EQ((*r.cloud)[2].x, -0.001f);
  EXPECT_FLOAT_EQ((*r.cloud)[2].y, 2.0f);
  EXPECT_FLOAT_EQ((*r.cloud)[2].z, 30.0f);
}

TEST(ReadXyz, UnparsableLineNamesItsNumber) {
  test::TempDir dir;
  const auto path = dir.write("t.xyz", "1 2 3\n4 five 6\n");
  try {
    readCloud(path);
    FAIL() << "expected a parse error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::PARSE_ERROR);
    EXPECT_NE(std::string(e.what()).find(":2:"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("column 2"), std::string::npos) << e.what();
  }
}

TEST(ReadXyz, TooFewColumnsIsAParseError) {
  test::TempDir dir;
  const auto path = dir.write("t.xyz", "1 2 3\n1 2\n");
  EXPECT_EQ(errorOf([&] { readCloud(path); }), ErrorCode::PARSE_ERROR);
}

TEST(ReadXyz, HeaderOnlyAllowedBeforeData) {
  test::TempDir dir;
  const auto path = dir.write("t.xyz", "1 2 3\nx y z\n");
  EXPECT_EQ(errorOf([&] { readCloud(path); }), ErrorCode::PARSE_ERROR);
}

TEST(ReadCloud, NonFinitePointsAreDroppedAndCounted) {
  test::TempDir dir;
  const auto path = dir.write("t.xyz", "1 2 3\nnan 0 0\n0 inf 0\n4 5 6\n0 0 -inf\n");
  const auto r = readCloud(path);
  EXPECT_EQ(r.points_in_file, 5u);
  EXPECT_EQ(r.dropped_non_finite, 3u);
  ASSERT_EQ(r.cloud->size(), 2u);
  EXPECT_FLOAT_EQ((*r.cloud)[1].z, 6.0f);
}

TEST(ReadCloud, NonFinitePointsInPcdAreDropped) {
  test::TempDir dir;
  Cloud c = smallCloud();
  c.push_back(pcl::PointXYZ(std::numeric_limits<float>::quiet_NaN(), 0.0f, 0.0f));
  c.is_dense = false;
  const auto path = dir.file("nan.pcd");
  writeCloud(path, c);
  const auto r = readCloud(path);
  EXPECT_EQ(r.dropped_non_finite, 1u);
  expectSameCloud(*r.cloud, smallCloud());
}

TEST(ReadCloud, AllNonFiniteIsEmptyInput) {
  test::TempDir dir;
  const auto path = dir.write("t.xyz", "nan nan nan\n");
  EXPECT_EQ(errorOf([&] { readCloud(path); }), ErrorCode::EMPTY_INPUT);
  io::CloudReadConfig options;
  options.allow_empty = true;
  EXPECT_EQ(readCloud(path, options).cloud->size(), 0u);
}

TEST(ReadCloud, EmptyFilesAreEmptyInput) {
  test::TempDir dir;
  const auto xyz = dir.write("t.xyz", "");
  EXPECT_EQ(errorOf([&] { readCloud(xyz); }), ErrorCode::EMPTY_INPUT);
  for (const char* ext : {"pcd", "ply"}) {
    const auto path = dir.file(std::string("empty.") + ext);
    writeCloud(path, Cloud());
    EXPECT_EQ(errorOf([&] { readCloud(path); }), ErrorCode::EMPTY_INPUT) << ext;
  }
}

TEST(ReadCloud, MissingFileAndUnknownFormat) {
  test::TempDir dir;
  EXPECT_EQ(errorOf([&] { readCloud(dir.file("absent.pcd")); }), ErrorCode::FILE_NOT_FOUND);
  EXPECT_EQ(errorOf([&] { readCloud(dir.file(".")); }), ErrorCode::FILE_NOT_FOUND);
  try {
    readCloud(dir.file(""));
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("is a directory"), std::string::npos) << e.what();
  }
  const auto las = dir.write("cloud.las", "1 2 3\n");
  EXPECT_EQ(errorOf([&] { readCloud(las); }), ErrorCode::UNKNOWN_FORMAT);
}

TEST(ReadCloud, MalformedPcdAndPlyAreParseErrors) {
  test::TempDir dir;
  const auto pcd = dir.write("bad.pcd", "this is not a pcd file\n");
  EXPECT_EQ(errorOf([&] { readCloud(pcd); }), ErrorCode::PARSE_ERROR);
  const auto ply =
      dir.write("bad.ply", "ply\nformat ascii 1.0\nelement vertex 2\nend_header\n1 2\n");
  EXPECT_EQ(errorOf([&] { readCloud(ply); }), ErrorCode::PARSE_ERROR);
  const auto no_xyz = dir.write("noxyz.pcd",
                                "VERSION 0.7\nFIELDS a b\nSIZE 4 4\nTYPE F F\nCOUNT 1 1\n"
                                "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2\n");
  EXPECT_EQ(errorOf([&] { readCloud(no_xyz); }), ErrorCode::PARSE_ERROR);
}

TEST(ReadCloud, AHeaderPromisingMorePointsThanTheFileHoldsIsRefusedBeforeAnyAllocation) {
  test::TempDir dir;
  const std::string head = "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\n";
  const auto count = dir.write("count.pcd", head +
                                                "COUNT 1000000000 1 1\nWIDTH 1\nHEIGHT 1\n"
                                                "POINTS 1\nDATA binary\n0123456789ab");
  const auto points = dir.write("points.pcd", head +
                                                  "COUNT 1 1 1\nWIDTH 100000000\nHEIGHT 1\n"
                                                  "POINTS 100000000\nDATA ascii\n1 2 3\n");
  // binary_compressed: 16 compressed bytes that claim 0xFFFFFFF0 uncompressed.
  std::string compressed = head +
                           "COUNT 1 1 1\nWIDTH 357913940\nHEIGHT 1\nPOINTS 357913940\n"
                           "DATA binary_compressed\n";
  const std::uint32_t sizes[2] = {16, 0xFFFFFFF0u};
  compressed.append(reinterpret_cast<const char*>(sizes), sizeof sizes);
  compressed.append(16, '\0');
  const auto lzf = dir.write("lzf.pcd", compressed);
  const auto mismatch = dir.write("wxh.pcd", head +
                                                 "COUNT 1 1 1\nWIDTH 2\nHEIGHT 1\n"
                                                 "POINTS 3\nDATA ascii\n1 2 3\n");
  for (const auto& path : {count, points, lzf, mismatch}) {
    try {
      readCloud(path);
      ADD_FAILURE() << path;
    } catch (const Error& e) {
      EXPECT_EQ(e.code(), ErrorCode::PARSE_ERROR) << e.what();
    }
  }
}

TEST(ReadCloud, Float32SurveyCoordinatesAreRefusedWithTheReason) {
  test::TempDir dir;
  const auto path = dir.write("utm.pcd",
                              "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                              "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n"
                              "612345 4423456 210\n612346 4423457 211\n");
  try {
    readCloud(path);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::PARSE_ERROR);
    EXPECT_NE(std::string(e.what()).find("float32"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("500.0 mm"), std::string::npos) << e.what();
  }
  // Near its origin a float32 cloud is fine.
  const auto local = dir.write("local.pcd",
                               "VERSION 0.7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\n"
                               "WIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1.5 2 3\n");
  EXPECT_EQ(readCloud(local).cloud->size(), 1u);
}

TEST(ReadCloud, AStrayPointDoesNotMoveTheRecentringOffset) {
  test::TempDir dir;
  std::string text;
  for (int i = 0; i < 50; ++i)
    text += std::to_string(612345.0 + 0.01 * i) + " 5123456.5 250.25\n";
  text += "1e7 1e7 1\n";
  const auto r = readCloud(dir.write("stray.xyz", text));
  EXPECT_NEAR(r.offset.x(), 612345.0, 1.0);
  EXPECT_NEAR((*r.cloud)[49].x + r.offset.x(), 612345.49, 1e-4) << "millimetres kept";
}

TEST(ReadCloud, DoublePrecisionPcdFields) {
  test::TempDir dir;
  const auto path = dir.write("d.pcd",
                              "VERSION 0.7\nFIELDS x y z\nSIZE 8 8 8\nTYPE F F F\nCOUNT 1 1 1\n"
                              "WIDTH 2\nHEIGHT 1\nPOINTS 2\nDATA ascii\n"
                              "500000.125 4000000.25 101.5\n500001.125 4000001.25 102.5\n");
  const auto r = readCloud(path);
  ASSERT_EQ(r.cloud->size(), 2u);
  // Recentred: survey coordinates keep millimetres through the offset.
  EXPECT_FALSE(r.offset.isZero());
  EXPECT_NEAR((*r.cloud)[0].x + r.offset.x(), 500000.125, 1e-6);
  EXPECT_NEAR((*r.cloud)[1].y + r.offset.y(), 4000001.25, 1e-6);
  EXPECT_NEAR((*r.cloud)[1].z + r.offset.z(), 102.5, 1e-6);
}

TEST(ReadCloud, SurveyCoordinatesAreRecentredWithoutLoss) {
  test::TempDir dir;
  const auto path =
      dir.write("utm.xyz", "612345.678 5123456.789 250.001\n612346.679 5123457.790 251.002\n");
  const auto r = readCloud(path);
  ASSERT_EQ(r.cloud->size(), 2u);
  EXPECT_LT(std::abs((*r.cloud)[0].x), 10.0f);
  EXPECT_NEAR((*r.cloud)[0].x + r.offset.x(), 612345.678, 1e-4);
  EXPECT_NEAR((*r.cloud)[1].y + r.offset.y(), 5123457.790, 1e-4);
  EXPECT_NEAR((*r.cloud)[0].z + r.offset.z(), 250.001, 1e-4);
  // Written back as text with the offset, the coordinates survive.
  const auto out = dir.file("back.xyz");
  writeCloud(out, *r.cloud, r.offset);
  std::ifstream in(out);
  double x = 0, y = 0, z = 0;
  in >> x >> y >> z;
  EXPECT_NEAR(x, 612345.678, 1e-4);
  EXPECT_NEAR(y, 5123456.789, 1e-4);
  EXPECT_NEAR(z, 250.001, 1e-4);
}

}  // namespace
}  // namespace dormant_tree_modeling
