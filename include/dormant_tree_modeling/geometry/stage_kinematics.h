#pragma once

#include <Eigen/Geometry>

namespace dormant_tree_modeling {
namespace geometry {

/// @brief Mounting of the slide and rotary stage on the platform (tf chain of
/// architecture.md: platform -> slide_base -> slide_carriage -> rotary_stage -> laser).
/// The platform frame has x towards the tree, y left, z up.
struct StageGeometry {
  Eigen::Vector3d platform_to_slide_base = Eigen::Vector3d::Zero();  ///< m
  Eigen::Vector3d carriage_to_stage = Eigen::Vector3d::Zero();       ///< m
  /// Laser optical centre in the rotating stage frame; zero puts it on the rotation axis, as
  /// the scan geometry of architecture.md assumes.
  Eigen::Vector3d stage_to_laser = Eigen::Vector3d::Zero();
};

/// @brief A platform pose from position (m) and heading (rad about z).
Eigen::Isometry3d platformPose(double x, double y, double z, double yaw);

/// @brief Pose of the (non-rotating) rotary_stage frame: where a view's points are expressed.
/// @param platform platform pose in the world
/// @param geometry mounting offsets
/// @param slide carriage position along the slide's y axis, m
Eigen::Isometry3d stagePose(const Eigen::Isometry3d& platform, const StageGeometry& geometry,
                            double slide);

/// @brief Pose of the laser at rotary angle theta (rad, about the stage's z axis).
Eigen::Isometry3d laserPose(const Eigen::Isometry3d& stage_pose, const StageGeometry& geometry,
                            double theta);

}  // namespace geometry
}  // namespace dormant_tree_modeling
