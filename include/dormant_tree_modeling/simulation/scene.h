#pragma once

#include <Eigen/Core>
#include <string>
#include <vector>

#include "dormant_tree_modeling/simulation/primitives.h"

namespace dormant_tree_modeling {
namespace simulation {

/// @brief One woody axis (trunk, branch, shoot) as a centreline with a radius per vertex (m).
struct BranchPolyline {
  Part part = Part::TRUNK;
  int parent = -1;  ///< index of the polyline it grows from; -1 for the trunk
  std::vector<Eigen::Vector3d> points;
  std::vector<double> radii;
};

/// @brief A tree: polyline 0 is its trunk (leader).
struct TreeObject {
  std::string preset;
  std::uint64_t seed = 0;
  std::vector<BranchPolyline> branches;
};

/// @brief A straight trellis wire.
struct Wire {
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::UnitX();
  double radius = 0.0015;
};

/// @brief A vertical post.
struct Post {
  Eigen::Vector3d base = Eigen::Vector3d::Zero();
  double height = 3.0;
  double radius = 0.06;
};

/// @brief Surface reflectances (diffuse, 0..1) used for echo energy and RSSI. Defaults are
/// typical values for the materials (bark and weathered wood 0.3-0.4, galvanised wire 0.5,
/// soil 0.2); the device is specified for targets down to 10 %.
struct Reflectances {
  double bark = 0.35;
  double wire = 0.5;
  double post = 0.4;
  double ground = 0.2;
};

/// @brief A static orchard scene in the tree frame: origin at the target trunk's base on the
/// ground, z up, x along the row, y across it (front of the tree at y < 0).
struct Scene {
  std::vector<TreeObject> trees;  ///< trees[0] is the target
  std::vector<Wire> wires;
  std::vector<Post> posts;
  bool has_ground = true;
  double ground_z = 0.0;
  double ground_half_extent = 30.0;  ///< the ground is the square |x|, |y| <= this (m)
  Reflectances reflectances;
};

/// @brief Save a scene as JSON ("dormant_tree_scene/1"). @throws Error IO_FAILURE
void saveScene(const Scene& scene, const std::string& path);

/// @brief Load a scene saved by saveScene(). @throws Error FILE_NOT_FOUND, PARSE_ERROR
Scene loadScene(const std::string& path);

}  // namespace simulation
}  // namespace dormant_tree_modeling
