#include "dormant_tree_modeling/io/pose_json.h"

#include <string>
#include <vector>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace io {

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
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();
  pose.linear() = Eigen::Quaterniond(q[3], q[0], q[1], q[2]).normalized().toRotationMatrix();
  pose.translation() = Eigen::Vector3d(t[0], t[1], t[2]);
  return pose;
}

}  // namespace io
}  // namespace dormant_tree_modeling
