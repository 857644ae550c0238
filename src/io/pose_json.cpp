#include "dormant_tree_modeling/io/pose_json.h"

#include <cmath>
#include <string>
#include <vector>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace io {

namespace {

// How far from 1 a written quaternion's norm may be (float rounding, 6-digit printing).
constexpr double QUATERNION_NORM_TOLERANCE = 1e-3;

}  // namespace

nlohmann::json poseToJson(const Eigen::Isometry3d& pose) {
  const Eigen::Quaterniond q(pose.linear());
  const Eigen::Vector3d t = pose.translation();
  return {{"translation", {t.x(), t.y(), t.z()}}, {"rotation_xyzw", {q.x(), q.y(), q.z(), q.w()}}};
}

std::optional<Eigen::Isometry3d> poseFromJson(const nlohmann::json& object, const char* key) {
  if (!object.contains(key))
    return std::nullopt;
  const auto& p = object.at(key);
  const auto t = p.at("translation").get<std::vector<double>>();
  const auto q = p.at("rotation_xyzw").get<std::vector<double>>();
  if (t.size() != 3 || q.size() != 4)
    throw Error(ErrorCode::PARSE_ERROR, std::string(key) + " needs 3 + 4 numbers");
  const Eigen::Vector3d translation(t[0], t[1], t[2]);
  const Eigen::Quaterniond rotation(q[3], q[0], q[1], q[2]);
  if (!translation.allFinite() || !rotation.coeffs().allFinite())
    throw Error(ErrorCode::PARSE_ERROR, std::string(key) + " holds a number that is not finite");
  // A rotation written as a unit quaternion, to the rounding of whoever wrote it: a [0,0,0,0]
  // or a scaled one is a mistake to report, not to normalise into some rotation.
  const double norm = rotation.norm();
  if (std::abs(norm - 1.0) > QUATERNION_NORM_TOLERANCE) {
    throw Error(ErrorCode::PARSE_ERROR, std::string(key) +
                                            ".rotation_xyzw must be a unit quaternion, its norm "
                                            "is " +
                                            std::to_string(norm));
  }
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = rotation.normalized().toRotationMatrix();
  pose.translation() = translation;
  return pose;
}

}  // namespace io
}  // namespace dormant_tree_modeling
