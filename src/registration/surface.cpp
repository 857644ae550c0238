#include "dormant_tree_modeling/registration/surface.h"

#include <Eigen/Eigenvalues>
#include <cmath>
#include <unordered_map>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/parallel.h"
#include "dormant_tree_modeling/modeling/point_index.h"

namespace dormant_tree_modeling {
namespace registration {

namespace {

// A voxel whose averaged view direction is shorter than this holds returns from opposite
// sides (both halves of a thin branch): its orientation is unknown.
constexpr double MIN_VIEW_AGREEMENT = 0.3;

struct VoxelKey {
  std::int64_t x, y, z;
  bool operator==(const VoxelKey& o) const { return x == o.x && y == o.y && z == o.z; }
};

struct VoxelHash {
  std::size_t operator()(const VoxelKey& k) const {
    return static_cast<std::size_t>(k.x * 73856093LL ^ k.y * 19349663LL ^ k.z * 83492791LL);
  }
};

}  // namespace

Eigen::Vector3d centroid(const Points& pts) {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  for (const auto& p : pts)
    c += p;
  return pts.empty() ? c : Eigen::Vector3d(c / static_cast<double>(pts.size()));
}

Points viewDirections(const Points& pts, const Eigen::Vector3d& sensor) {
  Points d(pts.size());
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Eigen::Vector3d v = sensor - pts[i];
    const double n = v.norm();
    d[i] = n > 0 ? Eigen::Vector3d(v / n) : Eigen::Vector3d::Zero();
  }
  return d;
}

Surface makeSurface(const Points& pts, const Points& view_dirs, double voxel,
                    int normal_neighbors) {
  if (!(voxel > 0))
    throw Error(ErrorCode::INVALID_ARGUMENT, "surface voxel must be > 0");
  if (!view_dirs.empty() && view_dirs.size() != pts.size())
    throw Error(ErrorCode::INVALID_ARGUMENT, "one view direction per point is needed");
  struct Acc {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero(), dir = Eigen::Vector3d::Zero();
    int n = 0;
  };
  std::unordered_map<VoxelKey, std::size_t, VoxelHash> slot;
  std::vector<Acc> acc;
  slot.reserve(pts.size() / 2 + 1);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const Eigen::Vector3d& p = pts[i];
    if (!p.allFinite())
      continue;
    const VoxelKey k{static_cast<std::int64_t>(std::floor(p.x() / voxel)),
                     static_cast<std::int64_t>(std::floor(p.y() / voxel)),
                     static_cast<std::int64_t>(std::floor(p.z() / voxel))};
    const auto [it, fresh] = slot.emplace(k, acc.size());
    if (fresh)
      acc.emplace_back();
    Acc& a = acc[it->second];
    a.sum += p;
    if (!view_dirs.empty())
      a.dir += view_dirs[i];
    ++a.n;
  }
  Surface s;
  s.points.reserve(acc.size());
  s.view_dirs.reserve(acc.size());
  for (const Acc& a : acc) {
    s.points.push_back(a.sum / a.n);
    const Eigen::Vector3d d = a.dir / a.n;
    s.view_dirs.push_back(d.norm() >= MIN_VIEW_AGREEMENT ? Eigen::Vector3d(d.normalized())
                                                         : Eigen::Vector3d::Zero());
  }
  s.normals.assign(s.points.size(), Eigen::Vector3d::Zero());
  if (s.points.size() < 5)
    return s;
  const modeling::PointIndex index(s.points);
  parallelFor(static_cast<int>(s.points.size()), [&](int i) {
    const auto nn = index.nearest(s.points[i], normal_neighbors);
    if (nn.size() < 5)
      return;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const int j : nn)
      mean += s.points[j];
    mean /= static_cast<double>(nn.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const int j : nn)
      cov += (s.points[j] - mean) * (s.points[j] - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
    Eigen::Vector3d n = es.eigenvectors().col(0);
    if (n.dot(s.view_dirs[i]) < 0)
      n = -n;
    s.normals[i] = n;
  });
  return s;
}

Surface transformed(const Surface& s, const Eigen::Isometry3d& t) {
  Surface o;
  o.points.reserve(s.size());
  for (const auto& p : s.points)
    o.points.push_back(t * p);
  o.normals.reserve(s.size());
  for (const auto& n : s.normals)
    o.normals.push_back(t.linear() * n);
  o.view_dirs.reserve(s.size());
  for (const auto& d : s.view_dirs)
    o.view_dirs.push_back(t.linear() * d);
  return o;
}

void append(Surface& a, const Surface& b) {
  a.points.insert(a.points.end(), b.points.begin(), b.points.end());
  a.normals.insert(a.normals.end(), b.normals.begin(), b.normals.end());
  a.view_dirs.insert(a.view_dirs.end(), b.view_dirs.begin(), b.view_dirs.end());
}

Pyramid makePyramid(const Points& pts, const Points& view_dirs, const std::vector<double>& voxels,
                    int normal_neighbors) {
  Pyramid p;
  p.voxels = voxels;
  for (const double v : voxels)
    p.levels.push_back(makeSurface(pts, view_dirs, v, normal_neighbors));
  return p;
}

Pyramid transformed(const Pyramid& p, const Eigen::Isometry3d& t) {
  Pyramid o;
  o.voxels = p.voxels;
  for (const auto& l : p.levels)
    o.levels.push_back(transformed(l, t));
  appendTransformed(o.axes, p.axes, t);
  return o;
}

void append(Pyramid& a, const Pyramid& b) {
  if (a.levels.empty()) {
    a = b;
    return;
  }
  if (a.voxels != b.voxels)
    throw Error(ErrorCode::INVALID_ARGUMENT, "pyramids with different levels cannot be merged");
  for (std::size_t i = 0; i < a.levels.size(); ++i)
    append(a.levels[i], b.levels[i]);
  appendTransformed(a.axes, b.axes, Eigen::Isometry3d::Identity());
}

}  // namespace registration
}  // namespace dormant_tree_modeling
