#include "dormant_tree_modeling/registration/icp.h"

#include <Eigen/Eigenvalues>
#include <algorithm>
#include <cmath>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/parallel.h"
#include "dormant_tree_modeling/modeling/point_index.h"
#include "dormant_tree_modeling/modeling/preprocess.h"

namespace dormant_tree_modeling {
namespace registration {

namespace {

constexpr double DEG = M_PI / 180.0;

// Unit normals of every point by PCA of its k nearest neighbours (zero where undefined).
std::vector<Eigen::Vector3d> normals(const Points& pts, const modeling::PointIndex& index, int k) {
  std::vector<Eigen::Vector3d> n(pts.size(), Eigen::Vector3d::Zero());
  parallelFor(static_cast<int>(pts.size()), [&](int i) {
    const auto nn = index.nearest(pts[i], k);
    if (nn.size() < 5)
      return;
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (const int j : nn)
      mean += pts[j];
    mean /= static_cast<double>(nn.size());
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (const int j : nn)
      cov += (pts[j] - mean) * (pts[j] - mean).transpose();
    const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> es(cov);
    n[i] = es.eigenvectors().col(0);
  });
  return n;
}

struct Match {
  int source, target;
  double residual;  // signed point-to-plane distance
  double distance;  // point-to-point distance
};

}  // namespace

void IcpConfig::validate() const {
  auto require = [](bool ok, const char* m) {
    if (!ok)
      throw Error(ErrorCode::INVALID_ARGUMENT, std::string("ICP: ") + m);
  };
  require(!voxels.empty(), "needs at least one level");
  for (const double v : voxels)
    require(v > 0, "voxel sizes must be > 0");
  require(distance_factor > 0, "distance_factor must be > 0");
  require(max_iterations > 0, "max_iterations must be > 0");
  require(trim > 0 && trim <= 1, "trim must be in (0, 1]");
  require(huber > 0, "huber must be > 0");
  require(normal_neighbors >= 5, "normal_neighbors must be >= 5");
  require(min_rotation_step > 0 && min_translation_step > 0, "convergence steps must be > 0");
}

IcpResult alignPointToPlane(const Points& source_in, const Points& target_in,
                            const Eigen::Isometry3d& guess, const IcpConfig& c) {
  c.validate();
  if (source_in.size() < 10 || target_in.size() < 10)
    throw Error(ErrorCode::EMPTY_INPUT, "ICP needs at least 10 points in each cloud");
  IcpResult r;
  r.transform = guess;
  for (std::size_t level = 0; level < c.voxels.size(); ++level) {
    const double voxel = c.voxels[level];
    const Points source = modeling::voxelDownsample(source_in, voxel);
    const Points target = modeling::voxelDownsample(target_in, voxel);
    const modeling::PointIndex index(target);
    const auto target_normals = normals(target, index, c.normal_neighbors);
    const double limit = c.distance_factor * voxel;
    const bool finest = level + 1 == c.voxels.size();
    std::vector<Match> matches(source.size());
    std::vector<char> valid(source.size());
    for (int it = 0; it < c.max_iterations; ++it) {
      ++r.iterations;
      parallelFor(static_cast<int>(source.size()), [&](int i) {
        const Eigen::Vector3d p = r.transform * source[i];
        const auto nn = index.nearest(p, 1);
        valid[i] = 0;
        if (nn.empty() || target_normals[nn[0]].isZero())
          return;
        const Eigen::Vector3d d = p - target[nn[0]];
        const double dist = d.norm();
        if (dist > limit)
          return;
        matches[i] = {i, nn[0], d.dot(target_normals[nn[0]]), dist};
        valid[i] = 1;
      });
      std::vector<Match> used;
      for (std::size_t i = 0; i < source.size(); ++i) {
        if (valid[i])
          used.push_back(matches[i]);
      }
      r.overlap = static_cast<double>(used.size()) / source.size();
      if (used.size() < 10)
        throw Error(ErrorCode::EMPTY_INPUT, "ICP: the clouds do not overlap at the guess");
      const std::size_t keep =
          std::max<std::size_t>(10, static_cast<std::size_t>(c.trim * used.size()));
      std::nth_element(used.begin(), used.begin() + (keep - 1), used.end(),
                       [](const Match& a, const Match& b) {
                         return std::abs(a.residual) < std::abs(b.residual);
                       });
      used.resize(keep);
      // Linearised point-to-plane step (small rotation w, translation t), Huber-weighted.
      Eigen::Matrix<double, 6, 6> A = Eigen::Matrix<double, 6, 6>::Zero();
      Eigen::Matrix<double, 6, 1> b = Eigen::Matrix<double, 6, 1>::Zero();
      double sq = 0;
      for (const auto& m : used) {
        const Eigen::Vector3d p = r.transform * source[m.source];
        const Eigen::Vector3d& n = target_normals[m.target];
        Eigen::Matrix<double, 6, 1> J;
        J << p.cross(n), n;
        const double e = m.residual;
        const double w = std::abs(e) <= c.huber ? 1.0 : c.huber / std::abs(e);
        A += w * J * J.transpose();
        b -= w * J * e;
        sq += e * e;
      }
      r.rmse = std::sqrt(sq / used.size());
      const Eigen::Matrix<double, 6, 1> x = A.ldlt().solve(b);
      if (!x.allFinite())
        break;
      Eigen::Isometry3d step = Eigen::Isometry3d::Identity();
      const double angle = x.head<3>().norm();
      if (angle > 0)
        step.linear() = Eigen::AngleAxisd(angle, x.head<3>() / angle).toRotationMatrix();
      step.translation() = x.tail<3>();
      r.transform = step * r.transform;
      if (angle < c.min_rotation_step * DEG && x.tail<3>().norm() < c.min_translation_step) {
        if (finest)
          r.converged = true;
        break;
      }
    }
  }
  return r;
}

}  // namespace registration
}  // namespace dormant_tree_modeling
