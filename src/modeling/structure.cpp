#include "dormant_tree_modeling/modeling/structure.h"

#include <algorithm>
#include <cmath>
#include <vector>

#include "dormant_tree_modeling/common/parallel.h"
#include "dormant_tree_modeling/modeling/point_index.h"

namespace dormant_tree_modeling {
namespace modeling {

double neighbourGrowthDimension(const Points& pts, const PointIndex& index, double radius_m,
                                std::size_t samples) {
  if (pts.empty() || samples == 0)
    return 0.0;
  const std::size_t stride = std::max<std::size_t>(1, pts.size() / samples);
  const int n = static_cast<int>((pts.size() + stride - 1) / stride);
  std::vector<double> near(n, 0.0), far(n, 0.0);
  parallelFor(n, [&](int k) {
    const Eigen::Vector3d& q = pts[static_cast<std::size_t>(k) * stride];
    // Each count includes the point itself, which a volume or a surface holds alike.
    near[k] = static_cast<double>(index.within(q, radius_m).size()) - 1.0;
    far[k] = static_cast<double>(index.within(q, 2.0 * radius_m).size()) - 1.0;
  });
  double near_sum = 0.0, far_sum = 0.0;
  for (int k = 0; k < n; ++k) {
    near_sum += near[k];
    far_sum += far[k];
  }
  return near_sum > 0.0 ? std::log2(far_sum / near_sum) : 0.0;
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
