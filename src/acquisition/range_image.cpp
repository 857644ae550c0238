#include "dormant_tree_modeling/acquisition/range_image.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>

#include <cmath>

namespace dormant_tree_modeling {
namespace acquisition {

void RangeImage::resize(int r, int c) {
  rows = r;
  cols = c;
  range.assign(static_cast<std::size_t>(r) * c, 0.0f);
}

double RangeImage::theta(int row) const {
  if (static_cast<std::size_t>(row) < row_theta.size())
    return row_theta[row];
  return theta0 + row * theta_step;
}

std::optional<double> RangeImage::middleStamp() const {
  const int n = static_cast<int>(row_stamp.size());
  const int mid = n / 2;
  // Outwards from the middle, the earlier row first at each distance.
  for (int d = 0; d <= mid; ++d) {
    for (const int i : {mid - d, mid + d}) {
      if (i >= 0 && i < n && row_stamp[i] > 0.0)
        return row_stamp[i];
    }
  }
  return std::nullopt;
}

double RangeImage::theta(int row, int col) const {
  const double rate =
      static_cast<std::size_t>(row) < row_theta_rate.size() ? row_theta_rate[row] : 0.0;
  return theta(row) + rate * col;
}

std::size_t RangeImage::validCount() const {
  std::size_t n = 0;
  for (const float r : range)
    n += r > 0.0f ? 1 : 0;
  return n;
}

void sphericalToCartesian(double rho, double theta, double phi, double& x, double& y, double& z) {
  const double s = std::sin(phi);
  x = rho * s * std::cos(theta);
  y = rho * s * std::sin(theta);
  z = -rho * std::cos(phi);
}

CloudPtr toCloud(const RangeImage& image, double phi_min, double phi_max) {
  auto cloud = std::make_shared<Cloud>();
  cloud->reserve(image.validCount());
  for (int i = 0; i < image.rows; ++i) {
    for (int j = 0; j < image.cols; ++j) {
      const double theta = image.theta(i, j);
      const float rho = image.at(i, j);
      const double phi = image.phi(j);
      if (!(rho > 0.0f) || phi < phi_min || phi >= phi_max)
        continue;
      double x, y, z;
      sphericalToCartesian(rho, theta, phi, x, y, z);
      cloud->push_back(
          pcl::PointXYZ(static_cast<float>(x), static_cast<float>(y), static_cast<float>(z)));
    }
  }
  return cloud;
}

}  // namespace acquisition
}  // namespace dormant_tree_modeling
