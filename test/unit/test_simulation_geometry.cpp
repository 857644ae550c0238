#include <gtest/gtest.h>

#include <cmath>

#include "dormant_tree_modeling/simulation/primitives.h"
#include "dormant_tree_modeling/simulation/ray_caster.h"

namespace dormant_tree_modeling {
namespace simulation {
namespace {

Ray ray(Eigen::Vector3d o, Eigen::Vector3d d) {
  return Ray{o, d.normalized()};
}

TEST(Frustum, CylinderHitFromOutside) {
  const Frustum cyl{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 0, 2), 1.0, 1.0};
  const auto hit = intersect(ray({-5, 0, 1}, {1, 0, 0}), cyl, 0.0, 100.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->first, 4.0, 1e-12);
  EXPECT_NEAR(hit->second.x(), -1.0, 1e-12);
  EXPECT_NEAR(hit->second.z(), 0.0, 1e-12);
}

TEST(Frustum, CylinderOffCentreChord) {
  // Ray at y = 0.6 through a unit cylinder: enters at x = -0.8.
  const Frustum cyl{Eigen::Vector3d(0, 0, -1), Eigen::Vector3d(0, 0, 1), 1.0, 1.0};
  const auto hit = intersect(ray({-3, 0.6, 0}, {1, 0, 0}), cyl, 0.0, 100.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->first, 2.2, 1e-12);
  EXPECT_NEAR(hit->second.x(), -0.8, 1e-12);
  EXPECT_NEAR(hit->second.y(), 0.6, 1e-12);
}

TEST(Frustum, ConeNormalTiltsWithTheTaper) {
  // Radius 1 at z = 0 to 0 at z = 2: at z = 1 the radius is 0.5.
  const Frustum cone{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 0, 2), 1.0, 0.0};
  const auto hit = intersect(ray({-5, 0, 1}, {1, 0, 0}), cone, 0.0, 100.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->first, 4.5, 1e-12);
  const Eigen::Vector3d expected = Eigen::Vector3d(-1, 0, 0.5).normalized();
  EXPECT_NEAR((hit->second - expected).norm(), 0.0, 1e-12);
}

TEST(Frustum, MissesBeyondTheSegmentAndOutsideTheRange) {
  const Frustum cyl{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 0, 2), 1.0, 1.0};
  EXPECT_FALSE(intersect(ray({-5, 0, 3}, {1, 0, 0}), cyl, 0.0, 100.0));
  EXPECT_FALSE(intersect(ray({-5, 1.5, 1}, {1, 0, 0}), cyl, 0.0, 100.0));
  EXPECT_FALSE(intersect(ray({-5, 0, 1}, {1, 0, 0}), cyl, 0.0, 3.9));
  EXPECT_FALSE(intersect(ray({-5, 0, 1}, {-1, 0, 0}), cyl, 0.0, 100.0));
}

TEST(Frustum, RayFromInsideHitsTheWall) {
  const Frustum cyl{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(0, 0, 2), 0.25, 0.25};
  const auto hit = intersect(ray({0, 0, 1}, {0, 1, 0}), cyl, 0.0, 100.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->first, 0.25, 1e-12);
}

TEST(Frustum, SlantedAxis) {
  // Axis along (1, 0, 1)/sqrt2 through the origin, radius 0.1; a ray along -y at the axis
  // point (0.5, 5, 0.5) meets the surface 0.1 before the axis.
  const Frustum cyl{Eigen::Vector3d(0, 0, 0), Eigen::Vector3d(1, 0, 1), 0.1, 0.1};
  const auto hit = intersect(ray({0.5, 5, 0.5}, {0, -1, 0}), cyl, 0.0, 100.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->first, 4.9, 1e-12);
}

TEST(Sphere, HitAndMiss) {
  const Sphere s{Eigen::Vector3d(1, 2, 3), 0.5};
  const auto hit = intersect(ray({1, 2, -3}, {0, 0, 1}), s, 0.0, 100.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->first, 5.5, 1e-12);
  EXPECT_NEAR(hit->second.z(), -1.0, 1e-12);
  EXPECT_FALSE(intersect(ray({1, 2.6, -3}, {0, 0, 1}), s, 0.0, 100.0));
}

Scene cylinderScene() {
  Scene scene;
  scene.has_ground = true;
  TreeObject t;
  BranchPolyline trunk;
  trunk.points = {{0, 0, 0}, {0, 0, 1}, {0, 0, 2}};
  trunk.radii = {0.1, 0.1, 0.1};
  t.branches.push_back(trunk);
  scene.trees.push_back(t);
  Wire w;
  w.a = {-10, 1, 1};
  w.b = {10, 1, 1};
  w.radius = 0.002;
  scene.wires.push_back(w);
  return scene;
}

TEST(RayCaster, NearestOfTreeWireAndGround) {
  const RayCaster caster(cylinderScene());
  auto hit = caster.cast(ray({-5, 0, 1.5}, {1, 0, 0}), 0.0, 100.0);
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 4.9, 1e-9);
  EXPECT_EQ(hit->label.part, Part::TRUNK);
  EXPECT_EQ(hit->label.object, 0);
  hit =
      caster.cast(ray({0.3, -5, 1.0}, {0, 1, 0}), 0.0, 100.0);  // passes the trunk, meets the wire
  ASSERT_TRUE(hit);
  EXPECT_NEAR(hit->t, 5.998, 1e-9);
  EXPECT_EQ(hit->label.part, Part::WIRE);
  hit = caster.cast(ray({3, 0, 2}, {0, 0, -1}), 0.0, 100.0);
  ASSERT_TRUE(hit);
  EXPECT_EQ(hit->label.part, Part::GROUND);
  EXPECT_NEAR(hit->t, 2.0, 1e-12);
  EXPECT_FALSE(caster.cast(ray({3, 0, 2}, {0, 0, 1}), 0.0, 100.0));
}

TEST(RayCaster, AgreesWithBruteForceOnAJointedPolyline) {
  Scene scene;
  scene.has_ground = false;
  TreeObject t;
  BranchPolyline b;
  for (int i = 0; i <= 40; ++i) {
    b.points.emplace_back(0.3 * std::sin(i * 0.2), 0.05 * i, 0.02 * i * i * 0.05);
    b.radii.push_back(0.05 - 0.001 * i);
  }
  t.branches.push_back(b);
  scene.trees.push_back(t);
  const RayCaster caster(scene);
  int hits = 0;
  for (int k = 0; k < 2000; ++k) {
    // Aim near the axis with an offset of up to 1.5 radii: hits, grazes and misses.
    const std::size_t v = static_cast<std::size_t>(k) % b.points.size();
    const Eigen::Vector3d aim =
        b.points[v] +
        1.5 * b.radii[v] * Eigen::Vector3d(std::sin(k * 1.3), std::cos(k * 0.9), std::sin(k * 0.4));
    const Ray r = ray({-3, 1, 0.5}, aim - Eigen::Vector3d(-3, 1, 0.5));
    double best = 1e9;
    for (std::size_t i = 0; i + 1 < b.points.size(); ++i) {
      const auto h = intersect(r, Frustum{b.points[i], b.points[i + 1], b.radii[i], b.radii[i + 1]},
                               0.0, best);
      if (h)
        best = h->first;
      if (i > 0) {
        const auto s = intersect(r, Sphere{b.points[i], b.radii[i]}, 0.0, best);
        if (s)
          best = s->first;
      }
    }
    const auto hit = caster.cast(r, 0.0, 1e9);
    if (best < 1e9) {
      ASSERT_TRUE(hit) << k;
      EXPECT_NEAR(hit->t, best, 1e-9) << k;
      ++hits;
    } else {
      EXPECT_FALSE(hit) << k;
    }
  }
  EXPECT_GT(hits, 500);   // the sample exercises hits
  EXPECT_LT(hits, 1950);  // and misses
}

}  // namespace
}  // namespace simulation
}  // namespace dormant_tree_modeling
