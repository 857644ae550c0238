#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "dormant_tree_modeling/modeling/branch_model.h"
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

/// @brief The branch candidates the search turned down as CSV, one per row under the header
/// centroid_x,centroid_y,centroid_z,points,reason,budget_spent: where a branch a user sees in
/// the cloud went, and why it is not in the model.
/// @param rejected the modeler's turned-down candidates (ModelResult::rejected_branches)
/// @param offset added to the centroids, as to the cylinders' centres
std::string turnedDownToCsv(const std::vector<modeling::RejectedBranch>& rejected,
                            const Eigen::Vector3d& offset = Eigen::Vector3d::Zero());

}  // namespace io
}  // namespace dormant_tree_modeling
