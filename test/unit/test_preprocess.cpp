// Preprocessing: the voxel grid and the floating-pixel mask against brute force; wires.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/random.h"
#include "dormant_tree_modeling/modeling/point_index.h"
#include "dormant_tree_modeling/modeling/preprocess.h"
#include "dormant_tree_modeling/modeling/structure.h"

namespace dormant_tree_modeling {
namespace modeling {
namespace {

/// A dense surface, a sparse haze and isolated points, off the origin and across cell borders
/// of every sign: every case of the cell shortcut and of the search behind it. (The k-d tree
/// is single precision: the modeler takes survey coordinates to a local origin first.)
Points mixedCloud(std::uint64_t seed) {
  Rng rng(seed);
  const Eigen::Vector3d far(-3.0, 12.0, 0.2);
  Points pts;
  for (int i = 0; i < 4000; ++i) {  // a 4 cm cylinder, 0.5 m tall
    const double a = rng.uniform(0.0, 2.0 * M_PI);
    pts.push_back(far +
                  Eigen::Vector3d(0.04 * std::cos(a), 0.04 * std::sin(a), rng.uniform(0.0, 0.5)));
  }
  for (int i = 0; i < 1500; ++i)  // haze: a few neighbours each, at best
    pts.push_back(far + Eigen::Vector3d(rng.uniform(-0.3, 0.3), rng.uniform(-0.3, 0.3),
                                        rng.uniform(0.0, 0.5)));
  return pts;
}

TEST(FloatingMask, SameAnswerAsABruteForceCount) {
  for (const std::uint64_t seed : {3u, 4u}) {
    const Points pts = mixedCloud(seed);
    for (const double radius : {0.01, 0.02, 0.035}) {
      for (const int min_neighbors : {1, 4, 9}) {
        const auto mask = floatingMask(pts, radius, min_neighbors);
        int floating = 0, mismatches = 0;
        for (std::size_t i = 0; i < pts.size(); ++i) {
          int others = 0;
          bool borderline = false;  // the k-d tree measures in single precision
          for (std::size_t j = 0; j < pts.size(); ++j) {
            const double d = (pts[j] - pts[i]).norm();
            others += j != i && d < radius;
            borderline = borderline || std::abs(d - radius) < 1e-6;
          }
          const bool expected = others < min_neighbors;
          floating += expected;
          mismatches += !borderline && expected != static_cast<bool>(mask[i]);
        }
        EXPECT_EQ(mismatches, 0) << "radius " << radius << " min " << min_neighbors;
        EXPECT_GT(floating, 0);
        EXPECT_LT(floating, static_cast<int>(pts.size()));
        // The k-d tree's single-precision count, to the last point.
        const PointIndex index(pts);
        for (std::size_t i = 0; i < pts.size(); ++i) {
          ASSERT_EQ(static_cast<bool>(mask[i]),
                    index.countWithin(pts[i], radius, min_neighbors + 1) <= min_neighbors)
              << "point " << i << " radius " << radius << " min " << min_neighbors;
        }
      }
    }
  }
}

TEST(MedianSpacing, GridSearchFindsTheIndexsNeighbours) {
  // A dense scan, and a sparse one whose neighbours lie several grid cells away.
  Rng rng(12);
  Points sparse;
  for (int i = 0; i < 3000; ++i)
    sparse.emplace_back(rng.uniform(-1.0, 1.0), rng.uniform(5.0, 6.0), rng.uniform(0.0, 0.4));
  for (const Points& pts : {mixedCloud(5), sparse}) {
    const double spacing = medianSpacing(pts);
    EXPECT_DOUBLE_EQ(spacing, medianSpacing(pts, PointIndex(pts)));
    EXPECT_GT(spacing, 0.0);
  }
  EXPECT_GT(medianSpacing(sparse), 0.02) << "the sparse cloud tests the widening search";
  EXPECT_EQ(medianSpacing(Points{{1, 2, 3}}), 0.0);
}

TEST(VoxelDownsample, OneMeanPerOccupiedCellInCellOrder) {
  Rng rng(9);
  Points pts;
  const Eigen::Vector3d far(-250000.0, 40.0, -12.0);
  for (int i = 0; i < 3000; ++i)
    pts.push_back(far +
                  Eigen::Vector3d(rng.uniform(0, 0.2), rng.uniform(0, 0.1), rng.normal(0, 0.05)));
  const double voxel = 0.02;
  const Points out = voxelDownsample(pts, voxel);
  // Brute force: cells as integer triples, sorted; one mean each.
  std::vector<std::pair<std::array<long, 3>, Eigen::Vector3d>> cells;
  for (const auto& p : pts) {
    cells.push_back({{static_cast<long>(std::floor(p.x() / voxel)),
                      static_cast<long>(std::floor(p.y() / voxel)),
                      static_cast<long>(std::floor(p.z() / voxel))},
                     p});
  }
  std::stable_sort(cells.begin(), cells.end(),
                   [](const auto& a, const auto& b) { return a.first < b.first; });
  Points expected;
  for (std::size_t i = 0; i < cells.size();) {
    Eigen::Vector3d sum = Eigen::Vector3d::Zero();
    std::size_t j = i;
    for (; j < cells.size() && cells[j].first == cells[i].first; ++j)
      sum += cells[j].second;
    expected.push_back(sum / static_cast<double>(j - i));
    i = j;
  }
  ASSERT_EQ(out.size(), expected.size());
  for (std::size_t i = 0; i < out.size(); ++i)
    EXPECT_EQ(out[i], expected[i]) << i;
}

TEST(VoxelDownsample, AGridTooFineForItsKeysIsAClearError) {
  // 2 km at 1 nm cells in every axis: 3 x 41 bits, more than one 64-bit key holds.
  const Points pts{Eigen::Vector3d::Zero(), Eigen::Vector3d(2000.0, 2000.0, 2000.0)};
  // (Survey coordinates themselves are fine: the keys count cells from the cloud's corner.)
  try {
    voxelDownsample(pts, 1e-9);
    FAIL() << "expected an error";
  } catch (const Error& e) {
    EXPECT_EQ(e.code(), ErrorCode::INVALID_ARGUMENT);
    EXPECT_NE(std::string(e.what()).find("voxel_size"), std::string::npos);
  }
}

TEST(Preprocess, AStrayPointFarFromTheTreeIsDroppedAndCountedNotFatal) {
  Rng rng(5);
  Points pts;
  for (int i = 0; i < 5000; ++i)
    pts.push_back(
        Eigen::Vector3d(rng.uniform(-1.0, 1.0), rng.uniform(-1.0, 1.0), rng.uniform(0.0, 3.0)));
  const Points clean = pts;
  pts.push_back(Eigen::Vector3d(1e7, 1e7, 1.0));
  pts.push_back(Eigen::Vector3d(0.0, 0.0, -2e6));
  pts.push_back(Eigen::Vector3d(30.0, 0.0, 1.0));  // a neighbour 30 m away is scene, not stray
  Points kept = pts;
  EXPECT_EQ(removeFarOutliers(kept), 2u);
  EXPECT_EQ(kept.size(), clean.size() + 1);
  ModelerConfig config;
  config.preprocess.remove_clutter = false;
  PreprocessStats stats;
  const Points out = preprocess(pts, config, &stats);  // would not fit a grid's keys with them
  EXPECT_EQ(stats.far_outliers, 2u);
  EXPECT_EQ(out, preprocess(kept, config, nullptr));
  Points tidy = clean;
  EXPECT_EQ(removeFarOutliers(tidy), 0u) << "a cloud without strays keeps every point";
}

TEST(Preprocess, AboveMaxModeledPointsACoarserGridKeepsTheCloudWithinIt) {
  Rng rng(8);
  Points wall;  // a scanned surface, 2 x 2 m at 2 mm: 1e6 cells, 40000 points
  for (int i = 0; i < 40000; ++i)
    wall.emplace_back(rng.uniform(0.0, 2.0), 0.001 * rng.normal(), rng.uniform(0.0, 2.0));
  ModelerConfig config;
  config.preprocess.remove_clutter = false;
  config.preprocess.voxel_size_m = 0.002;
  PreprocessStats stats;
  EXPECT_EQ(preprocess(wall, config, &stats).size(), stats.after_voxel);
  EXPECT_EQ(stats.capped, 0u) << "within the cap: the configured grid only";
  EXPECT_DOUBLE_EQ(stats.voxel_size, 0.002);
  config.preprocess.max_points = 10000;
  const Points capped = preprocess(wall, config, &stats);
  EXPECT_LE(capped.size(), 10000u);
  EXPECT_GT(capped.size(), 5000u) << "one coarser grid, not a collapse";
  EXPECT_EQ(stats.capped, stats.after_voxel - capped.size());
  EXPECT_GT(stats.voxel_size, 0.002);
  config.preprocess.max_points = 10;
  EXPECT_THROW(config.validate(), Error) << "a cap below any tree is refused";
}

TEST(NeighbourGrowthDimension, LinesSurfacesAndVolumesReadOneTwoAndThree) {
  Rng rng(9);
  Points line, surface, volume;
  for (int i = 0; i < 4000; ++i)  // a wire: 2 m, 3 mm noise
    line.emplace_back(rng.uniform(0.0, 2.0), 0.003 * rng.normal(), 0.003 * rng.normal());
  for (int i = 0; i < 40000; ++i)  // a trunk's bark: r 10 cm, 1 m tall, 3 mm noise
  {
    const double a = rng.uniform(0.0, 2.0 * M_PI), r = 0.10 + 0.003 * rng.normal();
    surface.emplace_back(r * std::cos(a), r * std::sin(a), rng.uniform(0.0, 1.0));
  }
  for (int i = 0; i < 40000; ++i)  // noise filling 1 m^3
    volume.emplace_back(rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0), rng.uniform(0.0, 1.0));
  const auto dimension = [](const Points& pts) {
    const PointIndex index(pts);
    return neighbourGrowthDimension(pts, index, 0.05, 1000);
  };
  EXPECT_NEAR(dimension(line), 1.0, 0.1);
  EXPECT_NEAR(dimension(surface), 2.0, 0.2);
  EXPECT_NEAR(dimension(volume), 3.0, 0.25);  // less at the cube's faces
  const Points lonely = {Eigen::Vector3d::Zero(), Eigen::Vector3d(1, 1, 1)};
  EXPECT_EQ(dimension(lonely), 0.0) << "no neighbours: no dimension";
}

/// 20000 points on an upright trunk of `radius` (m) about the z axis, from z0 to z1 (m).
Points uprightTrunk(Rng& rng, double radius, double z0, double z1) {
  Points pts;
  for (int i = 0; i < 20000; ++i) {
    const double a = rng.uniform(0.0, 2.0 * M_PI);
    pts.push_back(Eigen::Vector3d(radius * std::cos(a), radius * std::sin(a), rng.uniform(z0, z1)));
  }
  return pts;
}

/// A 5 cm trunk standing on z = 0, 1.5 m tall.
Points standingTrunk(Rng& rng) {
  return uprightTrunk(rng, 0.025, 0.0, 1.5);
}

/// Points within `radius` of the z axis, above `z`.
std::size_t countNearAxis(const Points& cloud, double radius, double z) {
  return std::count_if(cloud.begin(), cloud.end(), [&](const Eigen::Vector3d& p) {
    return std::hypot(p.x(), p.y()) < radius && p.z() > z;
  });
}

TEST(Preprocess, TakesANarrowStripOfGroundButNeitherATrunkBaseNorALowWire) {
  // A tree's crop across the row can hold a strip of ground narrower than it is long: 1.6 x
  // 0.5 m here, under the trunk. It goes and the trunk stays; the trunk alone, or with a
  // wire lying 5 cm above its foot, has no ground.
  ModelerConfig config;
  config.preprocess.remove_clutter = true;
  Rng rng(21);
  const Points trunk = standingTrunk(rng);
  Points strip;
  for (int i = 0; i < 6000; ++i) {
    strip.push_back(
        Eigen::Vector3d(rng.uniform(-0.8, 0.8), rng.uniform(-0.25, 0.25), rng.normal(0.0, 0.005)));
  }
  Points scene = trunk;
  scene.insert(scene.end(), strip.begin(), strip.end());
  PreprocessStats stats;
  const Points out = preprocess(scene, config, &stats);
  EXPECT_GT(stats.ground, 0u);
  const auto onGround = std::count_if(out.begin(), out.end(), [](const Eigen::Vector3d& p) {
    return p.z() < 0.02 && std::hypot(p.x(), p.y()) > 0.05;
  });
  EXPECT_EQ(onGround, 0) << "ground left beside the trunk";
  const Points trunk_voxels = voxelDownsample(trunk, config.preprocess.voxel_size_m);
  EXPECT_GT(countNearAxis(out, 0.05, 0.05), 0.95 * countNearAxis(trunk_voxels, 0.05, 0.05));

  PreprocessStats alone;
  preprocess(trunk, config, &alone);
  EXPECT_EQ(alone.ground, 0u) << "a trunk's base is no ground";
  Points wired = trunk;
  for (int i = 0; i < 3000; ++i) {
    wired.push_back(Eigen::Vector3d(rng.uniform(-0.8, 0.8), 0.1 + rng.normal(0.0, 0.003),
                                    0.05 + rng.normal(0.0, 0.003)));
  }
  PreprocessStats with_wire;
  preprocess(wired, config, &with_wire);
  EXPECT_EQ(with_wire.ground, 0u) << "a low wire is no ground";
}

TEST(Preprocess, RemovesAWireAndReportsItsDirection) {
  // A trunk, and a noisy 2 m wire beside it, not quite along x: the wire goes, its direction
  // is reported (the modeler takes short wire pieces as parallel to it), the trunk stays.
  Rng rng(3);
  Points pts = uprightTrunk(rng, 0.05, 0.1, 2.0);
  const Eigen::Vector3d along = Eigen::Vector3d(1.0, 0.2, 0.0).normalized();
  const Eigen::Vector3d start(-1.0, -0.1, 1.2);  // passes the trunk's axis 10 cm off
  for (int i = 0; i < 2000; ++i) {
    pts.push_back(start + rng.uniform(0.0, 2.0) * along +
                  Eigen::Vector3d(0.0, rng.normal(0.0, 0.004), rng.normal(0.0, 0.004)));
  }
  const ModelerConfig config;
  PreprocessStats stats;
  const Points out = preprocess(pts, config, &stats);
  ASSERT_EQ(stats.wire_directions.size(), 1u);
  EXPECT_GT(std::abs(stats.wire_directions[0].dot(along)), std::cos(1.0 * M_PI / 180.0));
  EXPECT_GT(stats.wires, 0u);
  const auto onTrunk = [](const Points& cloud) {
    return std::count_if(cloud.begin(), cloud.end(),
                         [](const Eigen::Vector3d& p) { return std::hypot(p.x(), p.y()) < 0.07; });
  };
  EXPECT_LT(out.size() - onTrunk(out), 20u) << "what is left of the wire";
  EXPECT_GT(onTrunk(out), 0.95 * onTrunk(voxelDownsample(pts, config.preprocess.voxel_size_m)));
}

TEST(Preprocess, RemovesAWireThatACropCutShorterThanAnyWire) {
  // A crop 0.8 m along the row around a narrow tree: a trunk, a noisy wire at 1.2 m crossing
  // the whole crop beside it, and a level branch along the row at 0.8 m from the trunk to the
  // crop's edge. The wire runs 0.8 m, under wire_min_length_m, but from edge to edge: it goes.
  // The branch, as straight and level, ends at the trunk: it stays.
  Rng rng(9);
  Points pts = uprightTrunk(rng, 0.035, 0.1, 2.0);
  for (int i = 0; i < 1500; ++i) {
    pts.push_back(Eigen::Vector3d(rng.uniform(-0.4, 0.4), 0.06 + rng.normal(0.0, 0.006),
                                  1.2 + rng.normal(0.0, 0.006)));
    pts.push_back(Eigen::Vector3d(rng.uniform(0.035, 0.4), rng.normal(0.0, 0.006),
                                  0.8 + rng.normal(0.0, 0.006)));
  }
  ModelerConfig config;
  config.preprocess.voxel_size_m = 0.0;
  ASSERT_GT(config.preprocess.wire_min_length_m, 0.8);
  PreprocessStats stats;
  const Points out = preprocess(pts, config, &stats);
  const auto near = [&](double y, double z) {
    return std::count_if(out.begin(), out.end(), [&](const Eigen::Vector3d& p) {
      return p.x() > 0.05 && std::hypot(p.y() - y, p.z() - z) < 0.015;
    });
  };
  EXPECT_EQ(stats.wire_directions.size(), 1u);
  EXPECT_LT(near(0.06, 1.2), 20) << "the wire is removed";
  EXPECT_GT(near(0.0, 0.8), 1200) << "the branch stays";
}

TEST(Preprocess, FindsAWireWhoseNeighbourhoodIsNoLineAndKeepsAGappyRowOfBranches) {
  // Three noisy wires along x across a 2 m crop. The top one has a branch trained along it
  // 4 cm off and shoots crossing it every 10 cm, so no 10 cm ball on it is a line and only
  // the wires below give the row's direction. Level branch pieces in line at another height,
  // with shoots like the top wire's and gaps between them, are no wire.
  Rng rng(5);
  Points pts;
  const auto wire = [&](double z, int n) {
    for (int i = 0; i < n; ++i)
      pts.emplace_back(rng.uniform(-1.0, 1.0), 0.06 + rng.normal(0.0, 0.004),
                       z + rng.normal(0.0, 0.004));
  };
  wire(0.6, 2000);
  wire(1.2, 2000);
  wire(1.8, 2000);
  const auto branch = [&](const Eigen::Vector3d& a, const Eigen::Vector3d& b, int n) {
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d p = a + rng.uniform(0.0, 1.0) * (b - a);
      pts.push_back(p + Eigen::Vector3d(rng.normal(0.0, 0.006), rng.normal(0.0, 0.006),
                                        rng.normal(0.0, 0.006)));
    }
  };
  branch({-1.0, 0.10, 1.8}, {1.0, 0.10, 1.8}, 3000);  // trained along the top wire
  for (double x = -0.95; x < 1.0; x += 0.1)           // shoots crossing it
    branch({x, 0.0, 1.70}, {x, 0.12, 1.90}, 150);
  const double pieces[][2] = {{-1.0, -0.75}, {-0.55, -0.3}, {-0.1, 0.15}, {0.35, 0.6}, {0.8, 1.0}};
  for (const auto& piece : pieces) {
    branch({piece[0], 0.3, 2.2}, {piece[1], 0.3, 2.2}, 400);
    for (double x = piece[0] + 0.05; x < piece[1]; x += 0.1)  // shoots: no local line either
      branch({x, 0.24, 2.1}, {x, 0.36, 2.3}, 150);
  }
  ModelerConfig config;
  config.preprocess.voxel_size_m = 0.0;
  PreprocessStats stats;
  const Points out = preprocess(pts, config, &stats);
  const auto near = [&](double y, double z) {
    return std::count_if(out.begin(), out.end(), [&](const Eigen::Vector3d& p) {
      return std::hypot(p.y() - y, p.z() - z) < 0.012;
    });
  };
  EXPECT_LT(near(0.06, 1.8), 40) << "the top wire is removed";
  EXPECT_LT(near(0.06, 1.2), 40);
  EXPECT_GT(near(0.30, 2.2), 1600) << "the branch pieces in line stay";
  EXPECT_GT(near(0.10, 1.8), 1500) << "the branch along the wire keeps its far side";
}

}  // namespace
}  // namespace modeling
}  // namespace dormant_tree_modeling
