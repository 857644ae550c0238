#pragma once

#include <Eigen/Geometry>
#include <optional>

namespace dormant_tree_modeling {
namespace registration {

/// @brief Two platform hints this close are one platform position: the slide moves within a
/// station are in the views' own frames, so the hint of an unmoved platform repeats exactly,
/// up to the rounding of its transport.
constexpr double SAME_STATION_MAX_OFFSET_M = 1e-3;
constexpr double SAME_STATION_MAX_TURN_RAD = 1.75e-4;  // 0.01 deg

/// @brief Whether two platform hints (station poses in a common frame) are one position.
bool samePlatformPlace(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b);

/// @brief Groups views arriving one by one into stations (ViewInput::station): a view joins
/// the previous view's station when both have a platform hint and the hints are one position
/// (samePlatformPlace); otherwise it starts a new station. A view without a hint always starts
/// its own: nothing says the platform stood still.
class StationGrouper {
 public:
  /// @brief The station of the next view.
  /// @param hint the view's platform hint, if any
  int next(const std::optional<Eigen::Isometry3d>& hint);

  /// @brief The views so far were handed off (registered or dropped): the next view starts a
  /// new station whatever its hint. Station numbers keep counting up.
  void restart() { last_hint_.reset(); }

 private:
  std::optional<Eigen::Isometry3d> last_hint_;
  int station_ = 0;
};

}  // namespace registration
}  // namespace dormant_tree_modeling
