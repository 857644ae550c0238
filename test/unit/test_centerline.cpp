// Centerline projection: exact values on a small polyline, and the height-ordered search of a
// rising polyline against measuring every segment.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <vector>

#include "dormant_tree_modeling/common/random.h"
#include "dormant_tree_modeling/modeling/trunk_model.h"

namespace dormant_tree_modeling {
namespace modeling {
namespace {

/// Every segment measured in index order, the first closest kept: what project() must return.
std::pair<double, double> bruteForce(const std::vector<Eigen::Vector3d>& v,
                                     const Eigen::Vector3d& p) {
  double best_d2 = std::numeric_limits<double>::infinity(), best_s = 0.0, start = 0.0;
  const std::size_t n = v.size() - 1;
  for (std::size_t i = 0; i < n; ++i) {
    const Eigen::Vector3d ab = v[i + 1] - v[i];
    const double length = ab.norm();
    if (length > 0.0) {
      const Eigen::Vector3d dir = ab / length;
      double t = (p - v[i]).dot(dir);
      if (i > 0)
        t = std::max(t, 0.0);
      if (i + 1 < n)
        t = std::min(t, length);
      const double d2 = (p - v[i] - t * dir).squaredNorm();
      if (d2 < best_d2) {
        best_d2 = d2;
        best_s = start + t;
      }
    }
    start += length;
  }
  return {best_s, std::sqrt(best_d2)};
}

TEST(Centerline, ProjectsOntoAnLShapedPolyline) {
  // Up 1 m, then 1 m along x: a point beside the corner, one past each end.
  const Centerline line({{0, 0, 0}, {0, 0, 1}, {1, 0, 1}});
  double d = 0.0;
  EXPECT_DOUBLE_EQ(line.project({0.2, 0, 0.5}, &d), 0.5);
  EXPECT_DOUBLE_EQ(d, 0.2);
  EXPECT_DOUBLE_EQ(line.project({0.5, 0.3, 1.0}, &d), 1.5);
  EXPECT_DOUBLE_EQ(d, 0.3);
  EXPECT_DOUBLE_EQ(line.project({0, 0.1, -0.4}, &d), -0.4) << "the first segment extends down";
  EXPECT_DOUBLE_EQ(d, 0.1);
  EXPECT_DOUBLE_EQ(line.project({1.25, 0, 1.0}, &d), 2.25) << "the last extends past its end";
  EXPECT_DOUBLE_EQ(d, 0.0);
  EXPECT_DOUBLE_EQ(line.length(), 2.0);
}

TEST(Centerline, HeightOrderedSearchMatchesEverySegmentMeasured) {
  // Rising polylines (the fast path) and ones that fold back down (every segment measured),
  // with points near and far, above, below and beside them.
  Rng rng(31);
  for (int trial = 0; trial < 60; ++trial) {
    const bool rising = trial % 3 != 0;
    std::vector<Eigen::Vector3d> v;
    Eigen::Vector3d at(rng.uniform(-0.1, 0.1), rng.uniform(-0.1, 0.1), 0.0);
    const int vertices = 2 + trial % 40;
    for (int k = 0; k < vertices; ++k) {
      v.push_back(at);
      const double rise = rising ? rng.uniform(0.005, 0.12) : rng.uniform(-0.08, 0.12);
      at += Eigen::Vector3d(rng.uniform(-0.05, 0.05), rng.uniform(-0.05, 0.05), rise);
    }
    if (trial % 7 == 0)
      v.insert(v.begin() + v.size() / 2, v[v.size() / 2]);  // a zero-length segment
    const Centerline line(v);
    const double top = v.back().z();
    for (int k = 0; k < 300; ++k) {
      const double reach = k % 2 ? 0.1 : 1.5;
      const Eigen::Vector3d p(rng.uniform(-reach, reach), rng.uniform(-reach, reach),
                              rng.uniform(-0.5, top + 0.5));
      double d = 0.0;
      const double s = line.project(p, &d);
      const auto [want_s, want_d] = bruteForce(v, p);
      ASSERT_NEAR(s, want_s, 1e-12) << "trial " << trial << " point " << k;
      ASSERT_NEAR(d, want_d, 1e-12) << "trial " << trial << " point " << k;
    }
  }
}

}  // namespace
}  // namespace modeling
}  // namespace dormant_tree_modeling
