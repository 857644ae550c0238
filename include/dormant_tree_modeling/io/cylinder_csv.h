#pragma once

#include <Eigen/Core>
#include <string>

#include "dormant_tree_modeling/modeling/tree_model.h"

namespace dormant_tree_modeling {
namespace io {

/// @brief The model as CSV, one cylinder per row (trunk bottom to top, then branches):
/// role,id,parent_id,center_x,center_y,center_z,axis_x,axis_y,axis_z,diameter_m,length_m,
/// num_points,inlier_ratio,attachment_height_m,angle_to_trunk_deg,trunk_diameter_m,
/// diameter_ratio,prune,diameter_resolved,diameter_min_m,diameter_max_m. Branch-only columns
/// are empty for trunk rows.
std::string cylindersToCsv(const modeling::TreeModel& model,
                           const Eigen::Vector3d& offset = Eigen::Vector3d::Zero());

}  // namespace io
}  // namespace dormant_tree_modeling
