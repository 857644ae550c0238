#include "dormant_tree_modeling/common/statistics.h"

#include <algorithm>

namespace dormant_tree_modeling {

double median(std::vector<double> values) {
  if (values.empty())
    return 0.0;
  const auto middle = values.begin() + static_cast<std::ptrdiff_t>(values.size() / 2);
  std::nth_element(values.begin(), middle, values.end());
  return *middle;
}

double quantileInPlace(std::vector<double>& values, double q) {
  if (values.empty())
    return 0.0;
  const auto k = static_cast<std::size_t>(q * static_cast<double>(values.size() - 1));
  std::nth_element(values.begin(), values.begin() + static_cast<std::ptrdiff_t>(k), values.end());
  return values[k];
}

double sigmaFromAbsoluteDeviations(std::vector<double> abs_deviations) {
  constexpr double NORMAL_MAD_TO_SIGMA = 1.4826;
  return NORMAL_MAD_TO_SIGMA * median(std::move(abs_deviations));
}

std::vector<double> axisSample(const std::vector<Eigen::Vector3d>& points, int axis,
                               std::size_t max_samples) {
  const std::size_t stride = std::max<std::size_t>(1, points.size() / max_samples);
  std::vector<double> out;
  out.reserve(points.size() / stride + 1);
  for (std::size_t i = 0; i < points.size(); i += stride)
    out.push_back(points[i](axis));
  return out;
}

}  // namespace dormant_tree_modeling
