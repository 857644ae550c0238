#include "dormant_tree_modeling/io/point_cloud_io.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <filesystem>

#include "dormant_tree_modeling/common/error.h"
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

CloudReadResult readCloud(const std::string& path, const CloudReadOptions& options) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw Error(ErrorCode::FILE_NOT_FOUND, "no such file: " + path);
  }
  CloudReadResult result;
  result.format = cloudFormatFromPath(path);
  detail::RawPoints raw;
  switch (result.format) {
    case CloudFormat::XYZ:
      raw = detail::readXyzText(path);
      break;
    case CloudFormat::PCD:
      raw = detail::readPclFile(path, false);
      break;
    case CloudFormat::PLY:
      raw = detail::readPclFile(path, true);
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
  Eigen::Vector3d min = Eigen::Vector3d::Constant(std::numeric_limits<double>::infinity());
  Eigen::Vector3d max = -min;
  for (const auto& p : finite) {
    max_abs = std::max(max_abs, p.cwiseAbs().maxCoeff());
    min = min.cwiseMin(p);
    max = max.cwiseMax(p);
  }
  if (!finite.empty() && max_abs > options.recenter_threshold) {
    // Round the offset to whole metres so that it is exact in any printed form.
    result.offset = (0.5 * (min + max)).array().round().matrix();
    result.offset.z() = std::round(min.z());
  }

  result.cloud = std::make_shared<Cloud>();
  result.cloud->reserve(finite.size());
  for (const auto& p : finite) {
    const Eigen::Vector3d q = p - result.offset;
    result.cloud->push_back(pcl::PointXYZ(static_cast<float>(q.x()), static_cast<float>(q.y()),
                                          static_cast<float>(q.z())));
  }
  return result;
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
