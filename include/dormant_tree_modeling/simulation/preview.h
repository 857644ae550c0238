#pragma once

#include <string>

#include "dormant_tree_modeling/common/cloud.h"
#include "dormant_tree_modeling/evaluation/ground_truth.h"
#include "dormant_tree_modeling/modeling/tree_model.h"

namespace dormant_tree_modeling {
namespace simulation {

/// @brief Render a front view (x right, z up) of a cloud with the true trunk (brown) and
/// primary branches (green) drawn over it, framed on the truth, and save it as PNG.
/// @param cloud points in the tree frame
/// @param truth ground truth of the tree
/// @param path output .png
/// @param width image width in pixels (height follows the tree's aspect)
/// @throws Error IO_FAILURE
void renderPreview(const Cloud& cloud, const evaluation::GroundTruth& truth,
                   const std::string& path, int width = 800);

/// @brief Render a front view of a cloud with a model's cylinders over it: trunk brown,
/// primary branches green, pruning candidates red; framed on the model. Saved as PNG.
/// @throws Error IO_FAILURE
void renderModelPreview(const Cloud& cloud, const modeling::TreeModel& model,
                        const std::string& path, int width = 800);

/// @brief Write a 16-bit binary PGM of a range image in millimetres (0 = invalid).
void writeRangePgm(const std::string& path, int rows, int cols, const float* ranges_m);

}  // namespace simulation
}  // namespace dormant_tree_modeling
