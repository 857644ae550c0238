#include "dormant_tree_modeling/io/point_cloud_io.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdio>
#include <filesystem>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/statistics.h"
#include "raw_points.h"

namespace dormant_tree_modeling {
namespace io {

namespace {

std::string lowerExtension(const std::string& path) {
  std::string ext = std::filesystem::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace

CloudFormat cloudFormatFromPath(const std::string& path) {
  const std::string ext = lowerExtension(path);
  if (ext == ".pcd")
    return CloudFormat::PCD;
  if (ext == ".ply")
    return CloudFormat::PLY;
  if (ext == ".xyz" || ext == ".txt" || ext == ".pts" || ext == ".asc" || ext == ".csv") {
    return CloudFormat::XYZ;
  }
  throw Error(ErrorCode::UNKNOWN_FORMAT,
              "unknown point cloud format '" + ext + "' for " + path +
                  " (expected .pcd, .ply, or text .xyz/.txt/.pts/.asc/.csv)");
}

namespace {

// Sample size for the offset's quantiles.
constexpr std::size_t OFFSET_SAMPLE = 100000;
// The ground's quantile: the offset's z sits at the bottom of the bulk.
constexpr double OFFSET_Z_QUANTILE = 0.01;

// The offset that brings survey coordinates near the origin: the median in x and y and a low
// quantile in z, of a sample, so that one stray point cannot move it; whole metres, so that it
// is exact in any printed form.
Eigen::Vector3d recentringOffset(const detail::RawPoints& pts) {
  Eigen::Vector3d offset;
  for (int a = 0; a < 3; ++a) {
    std::vector<double> sample = axisSample(pts, a, OFFSET_SAMPLE);
    offset(a) = std::round(quantileInPlace(sample, a == 2 ? OFFSET_Z_QUANTILE : 0.5));
  }
  return offset;
}

// float32 steps exceed 1 mm from 2^13 m on: a cloud stored so far from its origin lost the
// millimetres the diameters need before it was read (steps of 62.5 mm at 600 km).
constexpr double FLOAT32_MILLIMETRE_LIMIT_M = 8192.0;

[[noreturn]] void refuseCoarseFloats(const std::string& path, double max_abs) {
  const double step = std::ldexp(1.0, std::ilogb(max_abs) - 23);
  char buf[64];
  std::snprintf(buf, sizeof buf, "%.0f m, where float32 steps are %.1f mm", max_abs, 1000.0 * step);
  throw Error(ErrorCode::PARSE_ERROR,
              path + ": x/y/z are stored as float32 and reach " + buf +
                  ": the millimetres were lost when the file was written. Store the "
                  "coordinates as float64 (PCD SIZE 8, PLY double), or subtract an offset "
                  "before saving");
}

}  // namespace

CloudReadResult readCloud(const std::string& path, const CloudReadConfig& options) {
  std::error_code ec;
  if (std::filesystem::is_directory(path, ec))
    throw Error(ErrorCode::FILE_NOT_FOUND, path + " is a directory, not a point cloud file");
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw Error(ErrorCode::FILE_NOT_FOUND, "no such file: " + path);
  }
  CloudReadResult result;
  result.format = cloudFormatFromPath(path);
  detail::RawPoints raw;
  bool single_precision = false;
  switch (result.format) {
    case CloudFormat::XYZ:
      raw = detail::readXyzText(path);
      break;
    case CloudFormat::PCD:
      raw = detail::readPclFile(path, false, &single_precision);
      break;
    case CloudFormat::PLY:
      raw = detail::readPclFile(path, true, &single_precision);
      break;
  }
  result.points_in_file = raw.size();

  // Finite points only; the offset is chosen from them so one stray huge value cannot.
  detail::RawPoints finite;
  finite.reserve(raw.size());
  for (const auto& p : raw) {
    if (p.allFinite())
      finite.push_back(p);
  }
  result.dropped_non_finite = raw.size() - finite.size();
  if (finite.empty() && !options.allow_empty) {
    throw Error(ErrorCode::EMPTY_INPUT, "no finite points in " + path + " (" +
                                            std::to_string(raw.size()) + " points in the file, " +
                                            std::to_string(result.dropped_non_finite) +
                                            " NaN/Inf)");
  }

  double max_abs = 0.0;
  for (const auto& p : finite)
    max_abs = std::max(max_abs, p.cwiseAbs().maxCoeff());
  if (single_precision && max_abs >= FLOAT32_MILLIMETRE_LIMIT_M)
    refuseCoarseFloats(path, max_abs);
  if (!finite.empty() && max_abs > options.recenter_threshold)
    result.offset = recentringOffset(finite);

  result.cloud = std::make_shared<Cloud>();
  result.cloud->reserve(finite.size());
  for (const auto& p : finite) {
    const Eigen::Vector3d q = p - result.offset;
    result.cloud->push_back(pcl::PointXYZ(static_cast<float>(q.x()), static_cast<float>(q.y()),
                                          static_cast<float>(q.z())));
  }
  return result;
}

std::vector<Eigen::Vector3d> readPointsInFileFrame(const std::string& path) {
  const CloudReadResult cloud = readCloud(path);
  std::vector<Eigen::Vector3d> points;
  points.reserve(cloud.cloud->size());
  for (const auto& p : cloud.cloud->points)
    points.push_back(p.getVector3fMap().cast<double>() + cloud.offset);
  return points;
}

void writeCloud(const std::string& path, const Cloud& cloud, const Eigen::Vector3d& offset) {
  switch (cloudFormatFromPath(path)) {
    case CloudFormat::XYZ:
      detail::writeXyzText(path, cloud, offset);
      return;
    case CloudFormat::PCD:
      detail::writePclFile(path, cloud, offset, false);
      return;
    case CloudFormat::PLY:
      detail::writePclFile(path, cloud, offset, true);
      return;
  }
}

}  // namespace io
}  // namespace dormant_tree_modeling
