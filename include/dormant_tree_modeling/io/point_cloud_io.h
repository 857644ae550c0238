#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <string>
#include <vector>

#include "dormant_tree_modeling/common/cloud.h"

namespace dormant_tree_modeling {

template <typename Config>
class ConfigTable;

namespace io {

/// @brief Point cloud file formats the project reads and writes.
enum class CloudFormat {
  PCD,  ///< PCL's .pcd (ascii, binary or binary_compressed)
  PLY,  ///< Stanford .ply (ascii or binary), vertex x/y/z
  XYZ,  ///< text, one point per line: "x y z" plus ignored extra columns (.xyz .txt .pts .asc .csv)
};

/// @brief Format named by a path's extension (case-insensitive).
/// @param path file path
/// @throws Error UNKNOWN_FORMAT when the extension is not one of the supported ones
CloudFormat cloudFormatFromPath(const std::string& path);

/// @brief Options of readCloud().
struct CloudReadConfig {
  /// Recentre coordinates when any |coordinate| exceeds this (m). Clouds in survey coordinates
  /// (e.g. UTM, 10^5..10^6 m) lose centimetres in float; they are shifted by a double-precision
  /// offset first. Set to infinity to never recentre.
  double recenter_threshold = 1000.0;
  /// Accept a cloud with no finite points instead of throwing EMPTY_INPUT.
  bool allow_empty = false;
};

/// @brief A loaded cloud and what loading did to it.
struct CloudReadResult {
  CloudPtr cloud;                                    ///< finite points only, relative to offset
  Eigen::Vector3d offset = Eigen::Vector3d::Zero();  ///< original = cloud point + offset (m)
  std::size_t points_in_file = 0;                    ///< points the file held
  std::size_t dropped_non_finite = 0;     ///< points removed because a coordinate was NaN/Inf
  CloudFormat format = CloudFormat::XYZ;  ///< format that was read
};

/// @brief Read a PCD, PLY or XYZ-text cloud; the format comes from the extension.
/// @param path input file
/// @param options recentring and empty-cloud policy
/// @throws Error FILE_NOT_FOUND, UNKNOWN_FORMAT, PARSE_ERROR (with line number for text),
///         EMPTY_INPUT (no finite point, unless options.allow_empty)
CloudReadResult readCloud(const std::string& path, const CloudReadConfig& options = {});

/// @brief readCloud's points in double precision in the file's own frame (the offset put
/// back), for comparing with positions given in that frame (survey coordinates included).
std::vector<Eigen::Vector3d> readPointsInFileFrame(const std::string& path);

/// @brief Write a cloud as binary PCD, binary PLY or XYZ text, chosen by the extension.
/// @param path output file; its directory must exist
/// @param cloud points to write
/// @param offset added to every point before writing (text keeps it at double precision;
///        PCD and PLY store float32, so a large offset loses precision there)
/// @throws Error UNKNOWN_FORMAT, IO_FAILURE
void writeCloud(const std::string& path, const Cloud& cloud,
                const Eigen::Vector3d& offset = Eigen::Vector3d::Zero());

/// @brief The cloud file publisher node's parameters (launch/model_file.launch).
struct CloudPublisherConfig {
  std::string file;                  ///< .pcd, .ply or .xyz; required
  std::string frame_id = "orchard";  ///< frame of the published cloud
  double rate_hz = 0.0;              ///< republish rate; 0: once, latched
  /// @throws Error INVALID_ARGUMENT naming the field
  void validate() const;
};

/// @brief The keys of the cloud file publisher node: its parameters, docs/configuration.md.
const ConfigTable<CloudPublisherConfig>& cloudPublisherConfigTable();

}  // namespace io
}  // namespace dormant_tree_modeling
