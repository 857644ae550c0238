#include "dormant_tree_modeling/acquisition/view_processing.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cmath>

#include "dormant_tree_modeling/acquisition/sweep_assembler.h"
#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace acquisition {

void ViewProcessingConfig::validate() const {
  if (!(floating_threshold_m > 0))
    throw Error(ErrorCode::INVALID_ARGUMENT, "floating_threshold (rho_T) must be > 0 m");
  if (smoothing_iterations < 0 || smoothing_iterations > 20)
    throw Error(ErrorCode::INVALID_ARGUMENT, "smoothing_iterations must be in 0..20");
  if (!(phi_min_deg < phi_max_deg))
    throw Error(ErrorCode::INVALID_ARGUMENT, "phi_min_deg must be below phi_max_deg");
  isolation.validate();
}

ProcessedView processView(RangeImage& image, const Eigen::Isometry3d& stage_in_frame,
                          const Eigen::Vector2d& tree_hint, const ViewProcessingConfig& c,
                          std::optional<double> ground_hint) {
  c.validate();
  ProcessedView out;
  out.valid_pixels = image.validCount();
  if (out.valid_pixels == 0)
    throw Error(ErrorCode::EMPTY_INPUT, "the view has no valid return");
  out.floating_removed = removeFloatingPixels(image, c.floating_threshold_m);
  if (c.smoothing_iterations > 0)
    smoothRanges(image, c.floating_threshold_m, c.smoothing_iterations);
  constexpr double DEG = M_PI / 180.0;
  const CloudPtr stage_cloud = toCloud(image, c.phi_min_deg * DEG, c.phi_max_deg * DEG);
  auto cloud = std::make_shared<Cloud>();
  cloud->reserve(stage_cloud->size());
  for (const auto& p : *stage_cloud) {
    const Eigen::Vector3d q = stage_in_frame * Eigen::Vector3d(p.x, p.y, p.z);
    cloud->push_back(pcl::PointXYZ(static_cast<float>(q.x()), static_cast<float>(q.y()),
                                   static_cast<float>(q.z())));
  }
  if (!c.isolate) {
    out.cloud = cloud;
    return out;
  }
  out.isolation = isolateTarget(*cloud, stage_in_frame.translation(),
                                stage_in_frame.linear() * Eigen::Vector3d::UnitX(), tree_hint,
                                c.isolation, ground_hint);
  out.cloud = out.isolation.cloud;
  return out;
}

}  // namespace acquisition
}  // namespace dormant_tree_modeling
