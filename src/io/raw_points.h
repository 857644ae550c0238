#pragma once

// Private to the io area: format readers produce raw double-precision points, and
// point_cloud_io.cpp turns them into a cloud (dropping NaN/Inf, recentring) in one place.

#include <Eigen/Core>
#include <string>
#include <vector>

#include "dormant_tree_modeling/common/cloud.h"

namespace dormant_tree_modeling {
namespace io {
namespace detail {

using RawPoints = std::vector<Eigen::Vector3d>;

/// @brief Parse "x y z [extra...]" text; blank lines and lines starting with '#' or '//' are
/// skipped, separators are spaces, tabs, commas or semicolons. A header line of names (e.g.
/// "x y z") is accepted only as the first non-comment line.
/// @throws Error PARSE_ERROR naming the line number
RawPoints readXyzText(const std::string& path);

/// @brief Write "x y z" lines with enough digits to round-trip a double.
void writeXyzText(const std::string& path, const Cloud& cloud, const Eigen::Vector3d& offset);

/// @brief Read the x/y/z fields of a PCD or PLY file (float32, float64 or integer fields).
/// @param single_precision set to whether any of x/y/z is stored as float32
RawPoints readPclFile(const std::string& path, bool is_ply, bool* single_precision = nullptr);

/// @brief Write a binary PCD or binary PLY file.
void writePclFile(const std::string& path, const Cloud& cloud, const Eigen::Vector3d& offset,
                  bool is_ply);

}  // namespace detail
}  // namespace io
}  // namespace dormant_tree_modeling
