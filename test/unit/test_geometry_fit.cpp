#include <gtest/gtest.h>

#include <algorithm>

#include <Eigen/Geometry>
#include <cmath>
#include <cstdio>

#include "dormant_tree_modeling/common/random.h"
#include "dormant_tree_modeling/modeling/geometry_fit.h"

namespace dormant_tree_modeling {
namespace modeling {
namespace {

Points cylinderPoints(const Eigen::Vector3d& base, const Eigen::Vector3d& axis, double r,
                      double length, int n, double noise, std::uint64_t seed) {
  Rng rng(seed);
  const Eigen::Vector3d a = axis.normalized(), u = a.unitOrthogonal(), v = a.cross(u);
  Points pts;
  for (int i = 0; i < n; ++i) {
    const double t = rng.uniform(0.0, length), phi = rng.uniform(0.0, 2.0 * M_PI);
    const Eigen::Vector3d radial = std::cos(phi) * u + std::sin(phi) * v;
    pts.push_back(base + t * a + (r + rng.normal(0.0, noise)) * radial);
  }
  return pts;
}

TEST(Circle, ThroughThreePointsAndCollinear) {
  const auto c = circleThrough({1, 0}, {0, 1}, {-1, 0});
  ASSERT_TRUE(c);
  EXPECT_NEAR(c->center.norm(), 0.0, 1e-12);
  EXPECT_NEAR(c->radius, 1.0, 1e-12);
  EXPECT_FALSE(circleThrough({0, 0}, {1, 1}, {2, 2}));
}

TEST(Circle, LeastSquaresIsExactOnExactPoints) {
  Points2 pts;
  for (int i = 0; i < 12; ++i)
    pts.emplace_back(2.0 + 0.3 * std::cos(i * 0.5), -1.0 + 0.3 * std::sin(i * 0.5));
  const auto c = fitCircle(pts);
  ASSERT_TRUE(c);
  EXPECT_NEAR(c->center.x(), 2.0, 1e-9);
  EXPECT_NEAR(c->center.y(), -1.0, 1e-9);
  EXPECT_NEAR(c->radius, 0.3, 1e-9);
}

TEST(Circle, RobustFitIsHeldByTheRingNotByABranchBesideIt) {
  // A trunk's cross-section (r 5 cm, 12 mm radial noise, seen all around) fused with a branch
  // leaving it: 150 returns of a 3 cm ring 7 cm off. The disc's centroid and the least-squares
  // circle are dragged towards the branch; the robust fit, started at the trunk's predicted
  // centre, stays on the trunk.
  Rng rng(11);
  const Eigen::Vector2d trunk(0.01, -0.02), branch = trunk + Eigen::Vector2d(0.07, 0.0);
  const double sigma = 0.012;
  Points2 pts;
  for (int i = 0; i < 300; ++i) {
    const double a = rng.uniform(0.0, 2.0 * M_PI), r = 0.05 + rng.normal(0.0, sigma);
    pts.push_back(trunk + r * Eigen::Vector2d(std::cos(a), std::sin(a)));
  }
  for (int i = 0; i < 150; ++i) {
    const double a = rng.uniform(0.0, 2.0 * M_PI), r = 0.03 + rng.normal(0.0, sigma);
    pts.push_back(branch + r * Eigen::Vector2d(std::cos(a), std::sin(a)));
  }
  Eigen::Vector2d centroid = Eigen::Vector2d::Zero();
  for (const auto& p : pts)
    centroid += p;
  centroid /= static_cast<double>(pts.size());
  const auto plain = fitCircle(pts);
  ASSERT_TRUE(plain);
  const auto robust = robustCircle(pts, Circle{{0.0, 0.0}, 0.05}, 2.5 * sigma);
  ASSERT_TRUE(robust);
  std::printf(
      "[ INFO ] off the trunk's centre: centroid %.1f mm, least squares %.1f mm, "
      "robust %.1f mm\n",
      1000 * (centroid - trunk).norm(), 1000 * (plain->center - trunk).norm(),
      1000 * (robust->center - trunk).norm());
  EXPECT_GT((centroid - trunk).norm(), 0.015);
  EXPECT_GT((plain->center - trunk).norm(), 0.010);
  EXPECT_LT((robust->center - trunk).norm(), 0.4 * (centroid - trunk).norm());
  EXPECT_LT((robust->center - trunk).norm(), 0.008);
  EXPECT_NEAR(robust->radius, 0.05, 0.005);
}

TEST(Circle, RobustFitNeedsPointsInItsBand) {
  Points2 far;
  for (int k = 0; k < 7; ++k)
    far.emplace_back(std::cos(k * M_PI / 4), std::sin(k * M_PI / 4));  // a unit ring
  EXPECT_FALSE(robustCircle(far, Circle{{0, 0}, 0.05}, 0.01));
  EXPECT_FALSE(robustCircle(far, Circle{{0, 0}, 1.0}, 0.0));
  const auto ring = robustCircle(far, Circle{{0.01, 0}, 0.95}, 0.1);
  ASSERT_TRUE(ring);
  EXPECT_NEAR(ring->center.norm(), 0.0, 1e-6);
  EXPECT_NEAR(ring->radius, 1.0, 1e-6);
}

TEST(Circle, RansacIgnoresOutliersAndRespectsBounds) {
  Rng rng(3);
  Points2 pts;
  for (int i = 0; i < 200; ++i) {
    const double a = rng.uniform(0.0, 2.0 * M_PI);
    pts.emplace_back(0.05 * std::cos(a) + rng.normal(0.0, 0.001),
                     0.05 * std::sin(a) + rng.normal(0.0, 0.001));
  }
  for (int i = 0; i < 100; ++i)
    pts.emplace_back(rng.uniform(0.1, 0.4), rng.uniform(-0.2, 0.2));  // a branch
  CircleRansacConfig o;
  o.threshold = 0.004;
  std::vector<int> inliers;
  const auto c = ransacCircle(pts, o, &inliers);
  ASSERT_TRUE(c);
  EXPECT_NEAR(c->radius, 0.05, 0.002);
  EXPECT_NEAR(c->center.norm(), 0.0, 0.002);
  EXPECT_GE(inliers.size(), 195u);
  EXPECT_LE(inliers.size(), 215u);
  o.max_radius = 0.03;  // no circle of that size fits the ring
  const auto small = ransacCircle(pts, o);
  if (small) {
    EXPECT_LE(small->radius, 0.03);
  }
}

TEST(Circle, RansacKeepsItsCentreNearTheOrigin) {
  // A ring of 300 points 10 cm from the origin, and a ring of 100 about it.
  Points2 pts;
  for (int i = 0; i < 300; ++i) {
    const double a = 2.0 * M_PI * i / 300;
    pts.emplace_back(0.1 + 0.03 * std::cos(a), 0.03 * std::sin(a));
  }
  for (int i = 0; i < 100; ++i) {
    const double a = 2.0 * M_PI * i / 100;
    pts.emplace_back(0.02 * std::cos(a), 0.02 * std::sin(a));
  }
  CircleRansacConfig o;
  o.threshold = 0.002;
  const auto far = ransacCircle(pts, o);
  ASSERT_TRUE(far);
  EXPECT_NEAR(far->center.x(), 0.1, 0.001) << "the ring with the most points";
  o.max_center_offset = 0.01;
  const auto near = ransacCircle(pts, o);
  ASSERT_TRUE(near);
  EXPECT_LT(near->center.norm(), 0.001);
  EXPECT_NEAR(near->radius, 0.02, 0.001);
}

TEST(Cylinder, LeastSquaresRecoversAnInclinedCylinder) {
  const Eigen::Vector3d axis = Eigen::Vector3d(0.3, -0.2, 1.0).normalized();
  const Points pts = cylinderPoints({1, 2, 0}, axis, 0.04, 0.5, 400, 0.0, 1);
  const auto c = fitCylinder(pts, Eigen::Vector3d::UnitZ());
  ASSERT_TRUE(c);
  EXPECT_NEAR(c->radius, 0.04, 1e-6);
  EXPECT_NEAR(std::abs(c->axis.dot(axis)), 1.0, 1e-8);
  EXPECT_GT(c->axis.z(), 0.0);  // keeps the sign of the guess
  EXPECT_NEAR(c->length, 0.5, 0.02);
  const Eigen::Vector3d mid = Eigen::Vector3d(1, 2, 0) + 0.25 * axis;
  EXPECT_LT((c->center - mid).norm(), 0.02);
}

TEST(Cylinder, NoisyFitIsBiasedUpAndTheCorrectionRemovesIt) {
  const double r = 0.02, sigma = 0.006;
  const Points pts = cylinderPoints({0, 0, 0}, Eigen::Vector3d::UnitZ(), r, 0.3, 4000, sigma, 2);
  const auto c = fitCylinder(pts, Eigen::Vector3d::UnitZ());
  ASSERT_TRUE(c);
  const double corrected = noiseCorrectedRadius(*c, pts, sigma, 4.0 * sigma, 0.001);
  EXPECT_NEAR(corrected, r, 0.0008);
  EXPECT_GT(std::sqrt(c->mean_sq_distance), r + 0.0005);  // the plain second moment is inflated
}

TEST(Cylinder, RansacWithOutliersAndAxisBounds) {
  Points pts = cylinderPoints({0, 0, 0}, Eigen::Vector3d::UnitZ(), 0.03, 0.4, 600, 0.001, 4);
  const Points branch =
      cylinderPoints({0, 0, 0.2}, Eigen::Vector3d(1, 0, 0.2), 0.01, 0.3, 200, 0.001, 5);
  pts.insert(pts.end(), branch.begin(), branch.end());
  CylinderRansacConfig o;
  o.threshold = 0.004;
  o.max_axis_deviation = 0.3;
  std::vector<int> inliers;
  const auto c = ransacCylinder(pts, Eigen::Vector3d::UnitZ(), o, &inliers);
  ASSERT_TRUE(c);
  EXPECT_NEAR(c->radius, 0.03, 0.002);
  EXPECT_GT(c->axis.z(), std::cos(0.05));
  EXPECT_GE(inliers.size(), 590u);
  EXPECT_LE(inliers.size(), 660u);
}

TEST(Cylinder, ThinNoisyBranchFromTheSecondMoment) {
  // A 5 mm radius branch under 6 mm noise with a parallel shoot 3 cm away.
  const Eigen::Vector3d axis(1, 0, 0.1);
  Points pts = cylinderPoints({0, 0, 1}, axis, 0.005, 0.3, 1500, 0.006, 6);
  const Points shoot = cylinderPoints({0.1, 0.03, 1.01}, axis, 0.002, 0.1, 150, 0.006, 7);
  pts.insert(pts.end(), shoot.begin(), shoot.end());
  const auto c = fitThinCylinder(pts, Eigen::Vector3d(1, 0, 0), 0.006, 0.006, 0.03, 1);
  ASSERT_TRUE(c);
  EXPECT_NEAR(c->radius, 0.005, 0.0015);
  EXPECT_GT(std::abs(c->axis.dot(axis.normalized())), std::cos(3.0 * M_PI / 180.0));
  EXPECT_GT(c->axis.x(), 0.0);
}

/// A rod of radius r whose axis bends in a parabola leaving the chord by `sagitta` (m) at its
/// middle; returns displaced across the surface by Gaussian noise.
Points bentRodPoints(double r, double length, double sagitta, int n, double noise,
                     std::uint64_t seed) {
  Rng rng(seed);
  const double k = sagitta / (0.25 * length * length);
  Points pts;
  for (int i = 0; i < n; ++i) {
    const double t = rng.uniform(0.0, length), phi = rng.uniform(0.0, 2.0 * M_PI);
    const double x = t - 0.5 * length;
    const Eigen::Vector3d centre(t, 0.0, sagitta - k * x * x);
    const Eigen::Vector3d tangent = Eigen::Vector3d(1.0, 0.0, -2.0 * k * x).normalized();
    const Eigen::Vector3d u = Eigen::Vector3d::UnitY(), v = tangent.cross(u);
    const Eigen::Vector3d radial = std::cos(phi) * u + std::sin(phi) * v;
    pts.push_back(centre + (r + rng.normal(0.0, noise)) * radial);
  }
  return pts;
}

TEST(Cylinder, ThinRadiusFollowsABentAxis) {
  // A 4 mm branch bending 8 mm off its chord over 30 cm (about 3 degrees per 5 cm, as apple
  // primaries do), under 6 mm noise: its raw radius is the straight rod's, not wider.
  const double r = 0.004, sigma = 0.006;
  const auto straight = fitThinCylinder(bentRodPoints(r, 0.3, 0.0, 3000, sigma, 11),
                                        Eigen::Vector3d::UnitX(), sigma, 0.0, 0.03, 1);
  const auto bent = fitThinCylinder(bentRodPoints(r, 0.3, 0.008, 3000, sigma, 11),
                                    Eigen::Vector3d::UnitX(), sigma, 0.0, 0.03, 1);
  ASSERT_TRUE(straight && bent);
  // A straight axis reads this bend as 0.3 mm of radius.
  EXPECT_NEAR(bent->radius, straight->radius, 0.0001);
}

TEST(Cylinder, ThinRawRadiusLeavesShootsOut) {
  // A 5 mm branch under 6 mm noise over 30 cm with what an apple primary carries there: three
  // spurs (3 mm, 3 cm, square to it) and two shoots (2.5 mm, 15 cm, 40 degrees off it), their
  // points as many per area as the branch's. They cross 5 of its 8 slices; its raw radius
  // takes less than 0.6 mm from them, where a median over the slices takes 1.1 mm.
  const double r = 0.005, sigma = 0.006, length = 0.3;
  const Eigen::Vector3d axis = Eigen::Vector3d::UnitX();
  // Returns per m^2 of bark.
  const double density = 3000 / (2.0 * M_PI * r * length);
  const Points bare = cylinderPoints(Eigen::Vector3d::Zero(), axis, r, length, 3000, sigma, 21);
  Points shoots = bare;
  auto add = [&](double at, double phi, double off_deg, double radius, double len, int seed) {
    const double off = off_deg * M_PI / 180.0;
    const Eigen::Vector3d out(std::cos(off), std::sin(off) * std::cos(phi),
                              std::sin(off) * std::sin(phi));
    const int n = static_cast<int>(density * 2.0 * M_PI * radius * len);
    const Points p =
        cylinderPoints(Eigen::Vector3d(at, 0.0, 0.0), out, radius, len, n, sigma, seed);
    shoots.insert(shoots.end(), p.begin(), p.end());
  };
  add(0.05, 0.0, 90.0, 0.003, 0.03, 31);
  add(0.12, 2.0, 90.0, 0.003, 0.03, 32);
  add(0.22, 4.0, 90.0, 0.003, 0.03, 33);
  add(0.08, 1.0, 40.0, 0.0025, 0.15, 34);
  add(0.18, 3.0, 40.0, 0.0025, 0.15, 35);
  const auto clean = fitThinCylinder(bare, axis, sigma, 0.0, 0.03, 1);
  double spread = 0.0;
  const auto with_shoots = fitThinCylinder(shoots, axis, sigma, 0.0, 0.03, 1, nullptr, &spread);
  ASSERT_TRUE(clean && with_shoots);
  EXPECT_GE(with_shoots->radius, clean->radius);
  EXPECT_LT(with_shoots->radius - clean->radius, 0.0006);
  // Taking the branch out of its cluster takes its shoots' share too.
  EXPECT_GT(spread, clean->radius + 0.001);
}

/// A rod along x from r0 to r1 (m) over `length`, returns displaced across its surface.
Points taperedRodPoints(double r0, double r1, double length, int n, double noise,
                        std::uint64_t seed) {
  Rng rng(seed);
  Points pts;
  for (int i = 0; i < n; ++i) {
    const double t = rng.uniform(0.0, length), phi = rng.uniform(-M_PI, M_PI);
    const double r = r0 + (r1 - r0) * t / length + rng.normal(0.0, noise);
    pts.emplace_back(t, r * std::cos(phi), r * std::sin(phi));
  }
  return pts;
}

TEST(Cylinder, ThinRawRadiusIsTheTaperAtTheMiddle) {
  // A branch tapering from 8 to 4 mm over 30 cm, under 1 mm noise, reads as a 6 mm rod (its
  // middle, where its centre lies), not as its thinner end.
  const double length = 0.3, sigma = 0.001;
  const auto rod = fitThinCylinder(taperedRodPoints(0.006, 0.006, length, 4000, sigma, 17),
                                   Eigen::Vector3d::UnitX(), sigma, 0.0, 0.03, 1);
  const auto tapered = fitThinCylinder(taperedRodPoints(0.008, 0.004, length, 4000, sigma, 17),
                                       Eigen::Vector3d::UnitX(), sigma, 0.0, 0.03, 1);
  ASSERT_TRUE(rod && tapered);
  EXPECT_NEAR(tapered->center.x(), 0.5 * length, 0.01);
  EXPECT_NEAR(tapered->radius, rod->radius, 0.00015);
}

TEST(Cylinder, ThickTaperedScaffoldAtTheTrunkKeepsItsAxis) {
  // A scaffold tapering from 31 to 18 mm over 44 cm, under 3 mm noise, cut obliquely at its
  // far end, with the trunk's bark (70 mm) around its base and an axis guess 6 degrees off: as
  // a near part reaches the branch search. Slice centroids at both ends lie off the axis
  // (bark at the base, half a section at the cut); a line through them is tilted, the reach
  // then cuts each end's far side and the radius shrinks round by round. It reads as the
  // same branch alone and without the cut.
  const double length = 0.44, sigma = 0.003;
  const Points alone = taperedRodPoints(0.031, 0.018, length, 5000, sigma, 23);
  Points near;
  for (const auto& p : alone) {
    if (p.x() + 0.6 * p.y() < length - 0.03)
      near.push_back(p);
  }
  const Points trunk =
      cylinderPoints({-0.065, 0.0, -0.12}, Eigen::Vector3d::UnitZ(), 0.07, 0.24, 6000, sigma, 24);
  for (const auto& p : trunk) {
    if (p.x() > -0.02 && std::hypot(p.y(), p.z()) < 0.1)
      near.push_back(p);
  }
  const auto clean = fitThinCylinder(alone, Eigen::Vector3d::UnitX(), sigma, 0.0, 0.07, 1);
  const auto fit = fitThinCylinder(near, Eigen::Vector3d(1.0, 0.15, 0.0), sigma, 0.0, 0.07, 1);
  ASSERT_TRUE(clean && fit);
  EXPECT_NEAR(fit->radius, clean->radius, 0.001);
  EXPECT_GT(fit->axis.x(), std::cos(2.0 * M_PI / 180.0));
}

TEST(Cylinder, ThinAxisLeavesOutASliceBesideTheBranch) {
  // What a crossing branch's extraction leaves of a 13 mm primary under 6 mm noise: 9 cm of
  // it, and before its cut end only a secondary's returns, 25-35 mm beside its axis, filling
  // a slice of their own. A line through every slice's centre turns towards the secondary;
  // left out, the axis is the branch's.
  const double sigma = 0.006;
  Points pts =
      cylinderPoints({0.04, 0.0, 0.0}, Eigen::Vector3d::UnitX(), 0.0065, 0.09, 230, sigma, 41);
  const Points secondary = cylinderPoints({0.0, 0.025, 0.0}, Eigen::Vector3d(1.0, 0.25, 0.0), 0.003,
                                          0.04, 70, sigma, 42);
  pts.insert(pts.end(), secondary.begin(), secondary.end());
  const auto c = fitThinCylinder(pts, Eigen::Vector3d::UnitX(), sigma, 0.0, 0.017, 1);
  ASSERT_TRUE(c);
  EXPECT_GT(c->axis.x(), std::cos(2.0 * M_PI / 180.0));
  EXPECT_LT(std::abs(c->center.y()), 0.002);
}

TEST(Cylinder, ThickRadiusFromOneSide) {
  // A 14 mm scaffold under 3 mm noise seen all around, and only from one side (the leader
  // hides the other): the same raw radius, where a moment about the slices' centroids reads
  // the half-seen branch a quarter thinner.
  const double r = 0.014, sigma = 0.003;
  Rng rng(5);
  Points all, half;
  for (int i = 0; i < 4000; ++i) {
    const double t = rng.uniform(0.0, 0.3), phi = rng.uniform(-M_PI, M_PI);
    const Eigen::Vector3d p(t, (r + rng.normal(0.0, sigma)) * std::cos(phi),
                            (r + rng.normal(0.0, sigma)) * std::sin(phi));
    all.push_back(p);
    if (std::abs(phi) < 0.5 * M_PI)
      half.push_back(p);
  }
  const auto whole = fitThinCylinder(all, Eigen::Vector3d::UnitX(), sigma, 0.0, 0.04, 1);
  const auto side = fitThinCylinder(half, Eigen::Vector3d::UnitX(), sigma, 0.0, 0.04, 1);
  ASSERT_TRUE(whole && side);
  EXPECT_NEAR(side->radius, whole->radius, 0.0007);
}

TEST(Cylinder, DegenerateInputsGiveNothing) {
  EXPECT_FALSE(fitCylinder(Points{}, Eigen::Vector3d::UnitZ()));
  EXPECT_FALSE(fitCylinder(Points(10, Eigen::Vector3d::Zero()), Eigen::Vector3d::UnitZ()));
  EXPECT_FALSE(ransacCylinder(Points(3, Eigen::Vector3d::Ones()), Eigen::Vector3d::UnitZ(), {}));
  EXPECT_FALSE(fitCircle(Points2{{0, 0}, {1, 1}}));
}

TEST(KMeans, DeterministicAndSeparatesBlobs) {
  Rng rng(8);
  Points pts;
  for (int b = 0; b < 3; ++b) {
    for (int i = 0; i < 100; ++i)
      pts.emplace_back(b * 1.0 + rng.normal(0, 0.05), rng.normal(0, 0.05), 0.0);
  }
  const auto a = kMeans(pts, 3, 50, 42), b = kMeans(pts, 3, 50, 42);
  EXPECT_EQ(a, b);
  for (int blob = 0; blob < 3; ++blob) {
    for (int i = 1; i < 100; ++i)
      EXPECT_EQ(a[blob * 100 + i], a[blob * 100]);
  }
  EXPECT_NE(a[0], a[100]);
  EXPECT_NE(a[100], a[200]);
  EXPECT_NE(a[0], a[200]);
  // k larger than the distinct points: every label is used, none out of range.
  const auto few = kMeans(Points(5, Eigen::Vector3d::Ones()), 3, 10, 1);
  for (const int l : few)
    EXPECT_EQ(l, 0);
}

TEST(KMeans, ConvergedLabelsAreTheNearestCentres) {
  // Many clusters along a branch-like line: most points lie near two or more centres, so the
  // bounds that skip the scan, and the assignment made while seeding, are all exercised. Sorted
  // along the line, as the voxel grid leaves a cloud: seeding skips blocks far from a centre.
  Rng rng(21);
  Points pts;
  for (int i = 0; i < 20000; ++i)
    pts.emplace_back(rng.uniform() * 3.0, rng.normal(0, 0.03), rng.normal(0, 0.03));
  std::sort(pts.begin(), pts.end(),
            [](const Eigen::Vector3d& a, const Eigen::Vector3d& b) { return a.x() < b.x(); });
  const int k = 60;
  const auto labels = kMeans(pts, k, 300, 5);
  std::vector<Eigen::Vector3d> centres(k, Eigen::Vector3d::Zero());
  std::vector<int> counts(k, 0);
  for (std::size_t i = 0; i < pts.size(); ++i) {
    ASSERT_GE(labels[i], 0);
    ASSERT_LT(labels[i], k);
    centres[labels[i]] += pts[i];
    ++counts[labels[i]];
  }
  for (int c = 0; c < k; ++c) {
    ASSERT_GT(counts[c], 0);
    centres[c] /= counts[c];
  }
  // At convergence every point is (one of) the nearest to its own cluster's mean.
  int wrong = 0;
  for (std::size_t i = 0; i < pts.size(); ++i) {
    const double own = (pts[i] - centres[labels[i]]).squaredNorm();
    for (int c = 0; c < k; ++c)
      wrong += (pts[i] - centres[c]).squaredNorm() < own - 1e-12 ? 1 : 0;
  }
  EXPECT_EQ(wrong, 0);
}

}  // namespace
}  // namespace modeling
}  // namespace dormant_tree_modeling
