#include "dormant_tree_modeling/registration/branch_axes.h"

#include <algorithm>
#include <cmath>
#include <optional>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/parallel.h"
#include "dormant_tree_modeling/common/statistics.h"
#include "dormant_tree_modeling/modeling/point_index.h"

namespace dormant_tree_modeling {
namespace registration {

namespace {

struct Sample {
  Eigen::Vector3d point, direction, view;
  double radius, range;
};

// One side's half of a branch around one centre: the axis from PCA, the radius from the
// silhouette's width across the rays, the depth from the visible surface.
std::optional<Sample> fitPatch(const Points& pts, const Points& view_dirs,
                               const std::vector<double>& ranges, const std::vector<int>& nn,
                               const AxisConfig& c) {
  if (static_cast<int>(nn.size()) < c.min_points)
    return std::nullopt;
  Eigen::Vector3d mean_view = Eigen::Vector3d::Zero();
  Points patch;
  patch.reserve(nn.size());
  std::vector<double> patch_ranges;
  patch_ranges.reserve(nn.size());
  for (const int j : nn) {
    mean_view += view_dirs[j];
    patch.push_back(pts[j]);
    patch_ranges.push_back(ranges[j]);
  }
  mean_view /= static_cast<double>(nn.size());
  if (mean_view.norm() < c.min_view_agreement)
    return std::nullopt;
  Eigen::Vector3d centroid, eig;
  const Eigen::Vector3d axis = modeling::principalAxis(patch, &centroid, &eig);
  if (!(eig(2) >= c.linearity * std::max(eig(1), 1e-12)))
    return std::nullopt;
  const Eigen::Vector3d view = mean_view.normalized();
  if (std::abs(axis.dot(view)) > c.max_view_cos)
    return std::nullopt;
  // Across: normal to the axis and the rays; depth: the rays made normal to the axis.
  const Eigen::Vector3d across = axis.cross(view).normalized();
  const Eigen::Vector3d depth = across.cross(axis);
  // The silhouette from a slab of the patch (the ball would cut its edges short). Beams fan
  // evenly across a branch, so the offsets across are uniform over the silhouette: its width is
  // sqrt(12) standard deviations, however densely the station's views sampled it.
  const double slab = 0.25 * c.patch_m;
  std::vector<int> in_slab;
  double sum = 0, sum_sq = 0;
  for (std::size_t i = 0; i < patch.size(); ++i) {
    const Eigen::Vector3d d = patch[i] - centroid;
    if (std::abs(d.dot(axis)) > slab)
      continue;
    const double x = d.dot(across);
    sum += x;
    sum_sq += x * x;
    in_slab.push_back(static_cast<int>(i));
  }
  if (static_cast<int>(in_slab.size()) < c.min_points)
    return std::nullopt;
  const double n = static_cast<double>(in_slab.size());
  const double mid = sum / n;
  const double width = std::sqrt(12.0 * std::max(sum_sq / n - mid * mid, 0.0));
  const double range = median(patch_ranges);
  if (c.max_width_m > 0.0 && width > c.max_width_m + c.max_width_per_m * range)
    return std::nullopt;
  const double radius = 0.5 * (width - c.silhouette_growth_m - c.silhouette_growth_per_m * range) /
                        c.silhouette_diameter_gain;
  if (!(radius >= c.min_radius_m && radius <= c.max_radius_m))
    return std::nullopt;
  // A point at offset x from the axis (across) lies sqrt(r^2 - x^2) in front of it; beams
  // grazing the edge report the edge itself. The median of what is left is the axis depth.
  std::vector<double> offsets;
  offsets.reserve(in_slab.size());
  for (const int i : in_slab) {
    const Eigen::Vector3d d = patch[i] - centroid;
    const double x = d.dot(across) - mid;
    offsets.push_back(d.dot(depth) - std::sqrt(std::max(radius * radius - x * x, 0.0)));
  }
  const double behind = median(offsets);
  return Sample{centroid + mid * across + behind * depth, axis, view, radius, range};
}

}  // namespace

AxisSamples estimateAxes(const Points& pts, const Points& view_dirs,
                         const std::vector<double>& ranges, const Points& centres,
                         const AxisConfig& c) {
  c.validate();
  if (view_dirs.size() != pts.size() || ranges.size() != pts.size())
    throw Error(ErrorCode::INVALID_ARGUMENT,
                "branch axes: one view direction and one range per point are needed");
  AxisSamples out;
  if (pts.size() < static_cast<std::size_t>(c.min_points) || centres.empty())
    return out;
  const modeling::PointIndex index(pts);
  std::vector<std::optional<Sample>> found(centres.size());
  parallelFor(static_cast<int>(centres.size()), [&](int i) {
    found[i] = fitPatch(pts, view_dirs, ranges, index.within(centres[i], 0.5 * c.patch_m), c);
  });
  for (const auto& s : found) {
    if (!s)
      continue;
    out.points.push_back(s->point);
    out.directions.push_back(s->direction);
    out.view_dirs.push_back(s->view);
    out.radii.push_back(s->radius);
    out.ranges.push_back(s->range);
  }
  return out;
}

void appendTransformed(AxisSamples& a, const AxisSamples& b, const Eigen::Isometry3d& t) {
  a.points.reserve(a.size() + b.size());
  a.directions.reserve(a.size() + b.size());
  a.view_dirs.reserve(a.size() + b.size());
  for (std::size_t i = 0; i < b.size(); ++i) {
    a.points.push_back(t * b.points[i]);
    a.directions.push_back(t.linear() * b.directions[i]);
    a.view_dirs.push_back(t.linear() * b.view_dirs[i]);
  }
  a.radii.insert(a.radii.end(), b.radii.begin(), b.radii.end());
  a.ranges.insert(a.ranges.end(), b.ranges.begin(), b.ranges.end());
}

}  // namespace registration
}  // namespace dormant_tree_modeling
