#pragma once

#include <optional>

#include "dormant_tree_modeling/modeling/geometry_fit.h"

namespace dormant_tree_modeling {
namespace modeling {

/// @brief A straight ray leaving a trunk's axis: what a primary branch is near the trunk.
struct TrunkRay {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();      ///< on the trunk axis
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();  ///< unit, away from the trunk
  int votes = 0;  ///< points in the ray's Hough cell and its neighbours
};

/// @brief The ray from the trunk segment's axis through most of pts: a Hough transform over
/// the height it leaves the axis at (2 cm cells), its azimuth (5 deg) and its elevation above
/// the plane across the axis (5 deg steps from min to max). Fused candidates of a whorl of
/// thin branches (at centimetre noise the branches merge near the trunk) are parted along it.
/// @param trunk_segment its centre and axis define the trunk axis
/// @param min_elevation_deg, max_elevation_deg the elevations searched, degrees
/// @return nullopt when no point lies off the trunk axis
std::optional<TrunkRay> strongestRay(const Points& pts, const Cylinder& trunk_segment,
                                     double min_elevation_deg, double max_elevation_deg);

/// @brief Distance of p from the ray (from the origin on: points behind it are as far as the
/// origin).
double rayDistance(const TrunkRay& ray, const Eigen::Vector3d& p);

}  // namespace modeling
}  // namespace dormant_tree_modeling
