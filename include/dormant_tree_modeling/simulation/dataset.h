#pragma once

#include <cstdint>
#include <string>

#include "dormant_tree_modeling/acquisition/view_plan.h"
#include "dormant_tree_modeling/common/random.h"
#include "dormant_tree_modeling/geometry/stage_kinematics.h"
#include "dormant_tree_modeling/simulation/lms111_model.h"
#include "dormant_tree_modeling/simulation/orchard_generator.h"

namespace dormant_tree_modeling {
namespace simulation {

/// @brief Everything that defines a synthetic scan of one tree.
struct DatasetConfig {
  OrchardConfig orchard;
  std::uint64_t seed = 1;
  Lms111Config sensor;
  acquisition::ViewPlanConfig plan;
  geometry::StageGeometry geometry;
  /// Initial-guess error of each platform position (what odometry or an operator would give):
  /// horizontal offset up to this radius (m), heading error up to this angle (deg).
  double guess_max_translation = 0.5;
  double guess_max_yaw_deg = 20.0;
  double target_crop_margin = 0.15;  ///< m around the true tree for target.pcd (the hand crop)
  bool write_views = true;           ///< per-view range images and clouds
  int threads = 0;                   ///< 0 = all cores
};

/// @brief What writeDataset() produced.
struct DatasetSummary {
  int views = 0;
  std::size_t merged_points = 0;
  std::size_t target_points = 0;
  int primary_branches = 0;
  double simulate_seconds = 0.0;
};

/// @brief A random error of a platform position, in the platform's own frame (an operator or
/// odometry misjudging where the platform stands): horizontal offset uniform over a disc of
/// radius max_translation (m), height within ±5 cm, heading uniform within ±max_yaw_deg.
Eigen::Isometry3d randomPlatformError(Rng& rng, double max_translation, double max_yaw_deg);

/// @brief Generate the orchard, simulate every view of the plan and write, into `dir`:
/// scene.json, truth.json, views.json (true and initial-guess poses),
/// views/view_NN_range.pgm (16-bit, mm) and views/view_NN.pcd (rotary_stage frame),
/// merged.pcd / merged.ply (all views in the tree frame), target.pcd (the target tree cropped
/// by its true extent plus a margin, as the paper cropped by hand) and preview.png.
/// @throws Error on invalid options or when files cannot be written
DatasetSummary writeDataset(const DatasetConfig& options, const std::string& dir);

}  // namespace simulation
}  // namespace dormant_tree_modeling
