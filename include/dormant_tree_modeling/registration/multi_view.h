#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "dormant_tree_modeling/modeling/sensor_calibration.h"
#include "dormant_tree_modeling/registration/branch_axes.h"
#include "dormant_tree_modeling/registration/coarse_search.h"
#include "dormant_tree_modeling/registration/icp.h"

namespace dormant_tree_modeling {

template <typename Config>
class ConfigTable;

namespace registration {

/// @brief Settings of the multi-view registration (registration.yaml). Lengths in m.
struct RegistrationConfig {
  IcpConfig icp;
  CoarseSearchConfig coarse;
  AxisConfig axes;  ///< branch axes per station (used when icp.axis_pairs)
  /// ICP levels (from the coarsest) run on each coarse candidate before the best is refined.
  int candidate_levels = 1;
  int refinement_rounds = 3;     ///< joint rounds: every station against all the others
  std::size_t min_points = 500;  ///< fewer points (at the finest level): left out
  /// A station is kept only when this share of its points (finest level) lies on the others
  /// and the point-to-plane rmse stays below max_rmse: a view of another tree, or of nothing,
  /// does not pass.
  double min_overlap = 0.4;
  double max_rmse_m = 0.012;
  /// A station whose coarse candidates (its second place among them) end, after their ICP
  /// levels, in two places coarse.second_place_m or more apart, the second fitting with at
  /// least this share of the best one's overlap, is left out as ambiguous: a row of trees
  /// about as far apart as the search window is wide overlays itself shifted by one tree.
  double ambiguity_overlap_share = 0.5;
  bool use_hints = true;  ///< false: ignore the guesses (global search from scratch)
  /// @throws Error INVALID_ARGUMENT naming the bad field
  void validate() const;
};

/// @brief The keys of the registration settings (icp.*, axes.*, coarse.* and the fields above):
/// YAML loading, validation and docs/configuration.md.
const ConfigTable<RegistrationConfig>& registrationConfigTable();
/// @brief The keys of each nested part, also used to validate it alone.
const ConfigTable<IcpConfig>& icpConfigTable();
const ConfigTable<AxisConfig>& axisConfigTable();
const ConfigTable<CoarseSearchConfig>& coarseSearchConfigTable();

/// @brief Load settings from YAML (the `registration:` map or the root, groups as nested maps);
/// missing keys keep defaults, unknown keys are an error, renamed keys name their new name.
/// @throws Error FILE_NOT_FOUND, PARSE_ERROR, INVALID_ARGUMENT
RegistrationConfig loadRegistrationConfig(const std::string& path);

/// @brief Take the silhouette growth of the branch axes from a sensor calibration, and keep
/// axis samples within the silhouette widths its rods showed (AxisConfig::max_width_m: its
/// largest rod's, COVERAGE_RADIUS_SLACK wider): the growth was measured on those rods, and a
/// silhouette wider than about half the patch (AxisConfig::patch_m) is cut by it, read thin
/// and too near its sensor.
/// @return false (config unchanged: an ideal beam) when the calibration has no silhouette
bool applySensorCalibration(const modeling::SensorCalibration& calibration,
                            RegistrationConfig& config);

/// @brief One view to register. Views of one platform position (a station) are related by
/// exact slide moves and are registered as one rigid body.
struct ViewInput {
  std::string name;
  Points points;                                     ///< in the view's frame (z up)
  Eigen::Vector3d sensor = Eigen::Vector3d::Zero();  ///< where the laser was, view frame
  int station = 0;  ///< platform position; equal for views taken without moving the platform
  /// The view's pose in its station's frame (exact: the slide). Identity when the cloud is
  /// already in the platform frame.
  Eigen::Isometry3d in_station = Eigen::Isometry3d::Identity();
  /// Hint: the station frame's pose in a common world frame (odometry, operator, plan),
  /// possibly 0.5 m and 20 deg off; one per station is read (its first view's).
  std::optional<Eigen::Isometry3d> station_hint;
};

/// @brief What happened to one view.
struct ViewResult {
  std::string name;
  int station = 0;
  bool registered = false;
  /// View -> frame of the first registered view (Eq. 2).
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  double rmse = 0;     ///< m, point-to-plane against the other stations
  double overlap = 0;  ///< share of the view's points on the other stations' surfaces
  /// 0..1: overlap scaled by how well the surfaces pin every direction (a view that could slide
  /// along a trunk scores low even with a large overlap).
  double confidence = 0;
  std::string reason;  ///< why the view was left out (empty when registered)
};

/// @brief The registration of all views.
struct RegistrationResult {
  std::vector<ViewResult> views;  ///< in input order
  int stations = 0, stations_registered = 0;
  double seconds = 0;  ///< wall time, of which:
  double seconds_prepare = 0, seconds_placement = 0, seconds_refinement = 0;
};

/// @brief Register all views into the frame of the first view, without manual input: stations
/// from the exact slide poses; each further station placed by a global coarse search (around
/// the hints when there are any) and point-to-plane ICP with sensor-facing normals against all
/// stations placed so far; then joint rounds where every station is refined against all the
/// others, so errors do not pile up along a chain. Stations that do not fit are left out with a
/// reason, never merged wrong.
/// @throws Error INVALID_ARGUMENT on bad settings; EMPTY_INPUT when no view has points
RegistrationResult registerViews(const std::vector<ViewInput>& views,
                                 const RegistrationConfig& config);

/// @brief All registered views' points in the frame of the first view.
Points mergeRegistered(const std::vector<ViewInput>& views, const RegistrationResult& result);

}  // namespace registration
}  // namespace dormant_tree_modeling
