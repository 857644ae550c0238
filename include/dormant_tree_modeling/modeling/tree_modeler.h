#pragma once

#include <cstdint>
#include <string>
#include <vector>

#include "dormant_tree_modeling/common/cloud.h"
#include "dormant_tree_modeling/modeling/branch_model.h"
#include "dormant_tree_modeling/modeling/geometry_fit.h"
#include "dormant_tree_modeling/modeling/modeler_config.h"
#include "dormant_tree_modeling/modeling/preprocess.h"
#include "dormant_tree_modeling/modeling/tree_model.h"
#include "dormant_tree_modeling/modeling/trunk_search.h"

namespace dormant_tree_modeling {
namespace modeling {

/// @brief Per-point class of the modeled (downsampled, cleaned) cloud.
enum class PointClass : std::uint8_t { OTHER = 0, TRUNK = 1, PRIMARY = 2 };

/// @brief Everything one modeling run produced.
struct ModelResult {
  TreeModel model;
  Points points;                    ///< the cloud the model was computed from (preprocessed)
  std::vector<PointClass> classes;  ///< one per entry of `points`
  PreprocessStats preprocess;
  /// What preprocessing dropped or coarsened that the user should hear of (stray points far
  /// from the bulk, a grid coarser than voxel_size): one sentence each, for the tool and the node
  std::vector<std::string> notices;
  double noise_sigma = 0.0;        ///< range noise estimate used (m)
  double table_noise_sigma = 0.0;  ///< as the radius tables read it (TrunkModel::table_sigma), m
  double split_error = 0.0;        ///< e_t used (m)
  /// neighbourGrowthDimension of the modeled points: about 2 for scanned surfaces, 3 for a
  /// cloud filling a volume
  double structure_dimension = 0.0;
  int clusters = 0;  ///< after split and merge
  int trunk_clusters = 0;
  int primary_clusters = 0;
  std::vector<std::pair<std::string, double>> timings;  ///< stage name, seconds
  std::vector<RejectedBranch> rejected_branches;        ///< candidates turned down, and why
  std::vector<TrunkCandidate> trunk_candidates;         ///< trunk bases tracked
  /// points on other upright columns (TrunkCandidate::other_column), left out of the branch
  /// search
  int column_points = 0;
  /// of those, the ones within the trunk's reach: left out of its cylinders too
  int trunk_column_points = 0;
};

/// @brief The configuration as the stages run it: validated, and with noise.correct_bias
/// the radius tables filled (the noise part plus the calibration's footprint). For calling the
/// stages (modelTrunk, modelBranches) directly as TreeModeler does.
/// @throws Error INVALID_ARGUMENT
ModelerConfig stageConfig(const ModelerConfig& config);

/// @brief Algorithms 2 and 3 of the paper (docs/algorithms.md), plus the switchable additions of
/// ModelerConfig, from a point cloud of one tree to trunk and primary-branch cylinders.
class TreeModeler {
 public:
  /// @param config validated here; @throws Error INVALID_ARGUMENT
  explicit TreeModeler(const ModelerConfig& config);

  /// @brief Model one tree.
  /// @param cloud the tree, z up, in metres (finite points; readCloud drops NaN/Inf)
  /// @throws Error EMPTY_INPUT for a cloud without enough points, NO_TRUNK when no trunk is found
  ModelResult model(const Cloud& cloud) const;

  /// @brief Same, from double-precision points.
  ModelResult model(const Points& points) const;

  const ModelerConfig& config() const { return config_; }

 private:
  ModelerConfig config_;
};

}  // namespace modeling
}  // namespace dormant_tree_modeling
