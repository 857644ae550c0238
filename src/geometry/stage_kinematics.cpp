#include "dormant_tree_modeling/geometry/stage_kinematics.h"

namespace dormant_tree_modeling {
namespace geometry {

Eigen::Isometry3d platformPose(double x, double y, double z, double yaw) {
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.translation() = Eigen::Vector3d(x, y, z);
  pose.linear() = Eigen::AngleAxisd(yaw, Eigen::Vector3d::UnitZ()).toRotationMatrix();
  return pose;
}

Eigen::Isometry3d stagePose(const Eigen::Isometry3d& platform, const StageGeometry& geometry,
                            double slide) {
  Eigen::Isometry3d pose = platform;
  pose.translate(geometry.platform_to_slide_base + Eigen::Vector3d(0.0, slide, 0.0) +
                 geometry.carriage_to_stage);
  return pose;
}

Eigen::Isometry3d laserPose(const Eigen::Isometry3d& stage_pose, const StageGeometry& geometry,
                            double theta) {
  Eigen::Isometry3d pose = stage_pose;
  pose.rotate(Eigen::AngleAxisd(theta, Eigen::Vector3d::UnitZ()));
  pose.translate(geometry.stage_to_laser);
  return pose;
}

}  // namespace geometry
}  // namespace dormant_tree_modeling
