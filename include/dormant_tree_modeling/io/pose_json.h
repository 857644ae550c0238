#pragma once

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>
#include <optional>

namespace dormant_tree_modeling {
namespace io {

/// @brief A pose as views.json and registration.json write it:
/// {"translation": [x, y, z], "rotation_xyzw": [x, y, z, w]}.
nlohmann::json poseToJson(const Eigen::Isometry3d& pose);

/// @brief The pose under `key` in `object`, or none when the key is absent.
/// @throws Error PARSE_ERROR when the entry does not hold 3 + 4 numbers
std::optional<Eigen::Isometry3d> poseFromJson(const nlohmann::json& object, const char* key);

}  // namespace io
}  // namespace dormant_tree_modeling
