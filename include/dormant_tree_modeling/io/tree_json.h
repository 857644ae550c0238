#pragma once

#include <string>

#include "dormant_tree_modeling/evaluation/ground_truth.h"
#include "dormant_tree_modeling/modeling/tree_model.h"

namespace dormant_tree_modeling {
namespace io {

/// Format tags of docs/evaluation.md.
constexpr const char* MODEL_FORMAT = "dormant_tree_model/1";
constexpr const char* TRUTH_FORMAT = "dormant_tree_truth/1";

/// @brief Serialise a model as the model.json of docs/evaluation.md (extra keys: inlier_ratio,
/// attachment_height, angle_to_trunk_deg, trunk_diameter, diameter_ratio, prune,
/// diameter_resolved, diameter_min, diameter_max, runtime_s).
/// @param model the model
/// @param offset added to every centre (survey coordinates of the input cloud)
std::string modelToJson(const modeling::TreeModel& model,
                        const Eigen::Vector3d& offset = Eigen::Vector3d::Zero());

/// @brief Parse a model.json document. Unknown keys are ignored.
/// @throws Error PARSE_ERROR naming the offending key
modeling::TreeModel modelFromJson(const std::string& text);

/// @brief Serialise ground truth as truth.json.
std::string truthToJson(const evaluation::GroundTruth& truth);

/// @brief Parse a truth.json document; checks that each polyline has as many diameters as
/// points, at least two points, and positive diameters.
/// @throws Error PARSE_ERROR naming the offending key
evaluation::GroundTruth truthFromJson(const std::string& text);

/// @brief Read a whole text file. @throws Error FILE_NOT_FOUND, IO_FAILURE
std::string readTextFile(const std::string& path);

/// @brief Write a whole text file (replaces it). @throws Error IO_FAILURE
void writeTextFile(const std::string& path, const std::string& text);

/// @brief readTextFile + modelFromJson, with the path in error messages.
modeling::TreeModel readModelFile(const std::string& path);

/// @brief readTextFile + truthFromJson, with the path in error messages.
evaluation::GroundTruth readTruthFile(const std::string& path);

}  // namespace io
}  // namespace dormant_tree_modeling
