#include "dormant_tree_modeling/registration/stations.h"

namespace dormant_tree_modeling {
namespace registration {

bool samePlatformPlace(const Eigen::Isometry3d& a, const Eigen::Isometry3d& b) {
  const Eigen::Isometry3d d = a.inverse() * b;
  return d.translation().norm() < SAME_STATION_MAX_OFFSET_M &&
         Eigen::AngleAxisd(d.linear()).angle() < SAME_STATION_MAX_TURN_RAD;
}

int StationGrouper::next(const std::optional<Eigen::Isometry3d>& hint) {
  if (!hint || !last_hint_ || !samePlatformPlace(*hint, *last_hint_))
    ++station_;
  last_hint_ = hint;
  return station_;
}

}  // namespace registration
}  // namespace dormant_tree_modeling
