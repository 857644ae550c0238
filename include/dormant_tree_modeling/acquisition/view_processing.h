#pragma once

#include <optional>

#include <Eigen/Geometry>

#include "dormant_tree_modeling/acquisition/range_image.h"
#include "dormant_tree_modeling/acquisition/target_isolation.h"

namespace dormant_tree_modeling {
namespace acquisition {

/// @brief From one sweep's range image to the view cloud (docs/algorithms.md, section 1).
struct ViewProcessingConfig {
  double floating_threshold_m = 0.05;  ///< rho_T of Eq. 1
  int smoothing_iterations = 0;        ///< range smoothing passes (0: off; the modeler's
                                       ///< diameter calibration assumes unsmoothed ranges)
  double phi_min_deg = 0.0;            ///< beams kept: the tree lies in [0, 180) deg
  double phi_max_deg = 180.0;
  bool isolate = true;  ///< cut the target tree out (else the whole view)
  IsolationConfig isolation;

  /// @throws Error INVALID_ARGUMENT naming the bad field
  void validate() const;
};

/// @brief What became of a view.
struct ProcessedView {
  CloudPtr cloud;  ///< in the frame of stage_in_frame's parent (the platform)
  std::size_t valid_pixels = 0, floating_removed = 0;
  IsolationResult isolation;  ///< its cloud is `cloud`; empty when isolation is off
};

/// @brief Eq. 1, optional smoothing, spherical-to-Cartesian, into the platform frame, target
/// isolation. The image is modified (filtered) in place.
/// @param stage_in_frame the rotary_stage frame in the output frame (z up)
/// @param tree_hint where the plan expects the trunk, (x, y) in the output frame
/// @param ground_hint the ground's height in the output frame as the plan knows it, if it does
/// @throws Error EMPTY_INPUT for an image without valid pixels or without a tree
ProcessedView processView(RangeImage& image, const Eigen::Isometry3d& stage_in_frame,
                          const Eigen::Vector2d& tree_hint, const ViewProcessingConfig& config,
                          std::optional<double> ground_hint = std::nullopt);

}  // namespace acquisition
}  // namespace dormant_tree_modeling
