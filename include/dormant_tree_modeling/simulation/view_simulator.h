#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <vector>

#include "dormant_tree_modeling/acquisition/range_image.h"
#include "dormant_tree_modeling/acquisition/view_plan.h"
#include "dormant_tree_modeling/geometry/stage_kinematics.h"
#include "dormant_tree_modeling/simulation/lms111_model.h"

namespace dormant_tree_modeling {
namespace simulation {

/// @brief A simulated view: the range image the scan assembler would build, with the true
/// surface label of every pixel.
struct SimulatedView {
  acquisition::RangeImage image;  ///< rows = scan lines (theta), cols = beams (phi)
  std::vector<Label> labels;      ///< same layout as image.range
  Eigen::Isometry3d stage_pose = Eigen::Isometry3d::Identity();  ///< rotary_stage in the tree frame
};

/// @brief Simulate one rotary sweep (step-and-scan: one line per theta step).
/// @param model the sensor against its scene
/// @param stage_pose the rotary_stage frame in the scene frame
/// @param geometry mounting (laser offset on the stage)
/// @param sweep theta range and step (other fields unused)
/// @param seed, view_index noise streams: the same values give the same view, on any
///        number of threads
/// @param threads 0 = all cores
SimulatedView simulateView(const Lms111Model& model, const Eigen::Isometry3d& stage_pose,
                           const geometry::StageGeometry& geometry,
                           const acquisition::ViewPlanConfig& sweep, std::uint64_t seed,
                           int view_index, int threads = 0);

}  // namespace simulation
}  // namespace dormant_tree_modeling
