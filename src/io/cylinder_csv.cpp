#include "dormant_tree_modeling/io/cylinder_csv.h"

#include <cmath>
#include <cstdio>

namespace dormant_tree_modeling {
namespace io {

namespace {

std::string common(const char* role, const modeling::CylinderModel& c, int parent,
                   const Eigen::Vector3d& offset) {
  char buf[384];
  const Eigen::Vector3d p = c.center + offset;
  std::snprintf(buf, sizeof(buf), "%s,%d,%d,%.6f,%.6f,%.6f,%.6f,%.6f,%.6f,%.5f,%.4f,%zu,%.3f", role,
                c.id, parent, p.x(), p.y(), p.z(), c.axis.x(), c.axis.y(), c.axis.z(), c.diameter,
                c.length, c.num_points, c.inlier_ratio);
  return buf;
}

}  // namespace

std::string cylindersToCsv(const modeling::TreeModel& model, const Eigen::Vector3d& offset) {
  std::string out =
      "role,id,parent_id,center_x,center_y,center_z,axis_x,axis_y,axis_z,diameter_m,length_m,num_"
      "points,"
      "inlier_ratio,attachment_height_m,angle_to_trunk_deg,trunk_diameter_m,diameter_ratio,prune,"
      "diameter_resolved,diameter_min_m,diameter_max_m\n";
  for (const auto& c : model.trunk)
    out += common("trunk", c, -1, offset) + ",,,,,,,,\n";
  for (const auto& b : model.primary_branches) {
    char buf[200];
    std::snprintf(buf, sizeof(buf), ",%.4f,%.2f,%.5f,%.3f,%d,%d,%.5f,%.5f\n",
                  b.measurement.attachment_height, b.measurement.angle_to_trunk * 180.0 / M_PI,
                  b.measurement.trunk_diameter, b.measurement.diameter_ratio,
                  b.measurement.prune ? 1 : 0, b.measurement.diameter_resolved ? 1 : 0,
                  b.measurement.diameter_min, b.measurement.diameter_max);
    out += common("primary_branch", b.cylinder, b.trunk_segment, offset) + buf;
  }
  return out;
}

std::string turnedDownToCsv(const std::vector<modeling::RejectedBranch>& rejected,
                            const Eigen::Vector3d& offset) {
  std::string out = "centroid_x,centroid_y,centroid_z,points,reason,budget_spent\n";
  for (const auto& r : rejected) {
    char buf[192];
    const Eigen::Vector3d p = r.centroid + offset;
    std::snprintf(buf, sizeof(buf), "%.6f,%.6f,%.6f,%d,%s,%d\n", p.x(), p.y(), p.z(), r.points,
                  modeling::branchRejectionText(r.reason), r.budget_spent ? 1 : 0);
    out += buf;
  }
  return out;
}

}  // namespace io
}  // namespace dormant_tree_modeling
