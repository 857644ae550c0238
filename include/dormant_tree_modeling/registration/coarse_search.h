#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <vector>

#include "dormant_tree_modeling/registration/surface.h"

namespace dormant_tree_modeling {
namespace registration {

/// @brief Global search for where a station lies relative to the registered ones, when the
/// platform moved: only its heading and position matter (the platform stands upright).
/// Lengths in m, angles in degrees.
struct CoarseSearchConfig {
  double cell_m = 0.05;  ///< occupancy grid cell
  /// With a hint: headings within +-yaw_window of it, positions within +-xy_window, heights
  /// within +-z_window. Without one: the full turn, and xy/z windows around the centroids.
  double yaw_window_deg = 30.0;
  double yaw_step_deg = 2.0;
  double xy_window_m = 1.0;
  double z_window_m = 0.1;
  double z_window_unhinted_m = 2.0;
  double z_step_m = 0.05;
  int candidates = 3;  ///< best distinct poses returned
  /// The best heading's second place is also returned: its best shift at least this far from
  /// its best one. A row of trees repeating within the window shows there as a second peak.
  double second_place_m = 0.25;
  /// @throws Error INVALID_ARGUMENT naming the bad field
  void validate() const;
};

/// @brief One scored pose.
struct CoarseCandidate {
  Eigen::Isometry3d transform = Eigen::Isometry3d::Identity();  ///< source -> target
  double score = 0;  ///< share of source cells that land on occupied target cells
};

/// @brief Best source -> target poses by occupancy overlap: for each heading, the horizontal
/// shift that best overlays the two top-down footprints (the tree's trunk and branches), then
/// the height that best overlays the 3-D cells.
/// @param hint initial source -> target guess, or none (full search)
/// @returns up to config.candidates poses, best first, then the best heading's second place
/// (CoarseSearchConfig::second_place_m) when its footprints overlap at all
/// @throws Error EMPTY_INPUT when either set is empty
std::vector<CoarseCandidate> coarseSearch(const Points& source, const Points& target,
                                          const std::optional<Eigen::Isometry3d>& hint,
                                          const CoarseSearchConfig& config);

}  // namespace registration
}  // namespace dormant_tree_modeling
