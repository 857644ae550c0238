#include "dormant_tree_modeling/modeling/tree_model.h"

namespace dormant_tree_modeling {
namespace modeling {

namespace {

void transformCylinder(CylinderModel& c, const Eigen::Isometry3d& pose) {
  c.center = pose * c.center;
  c.axis = (pose.linear() * c.axis).normalized();
}

}  // namespace

TreeModel transformModel(const TreeModel& model, const Eigen::Isometry3d& pose) {
  TreeModel out = model;
  for (auto& c : out.trunk)
    transformCylinder(c, pose);
  for (auto& b : out.primary_branches)
    transformCylinder(b.cylinder, pose);
  return out;
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
