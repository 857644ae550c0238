#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "dormant_tree_modeling/simulation/primitives.h"
#include "dormant_tree_modeling/simulation/scene.h"

namespace dormant_tree_modeling {
namespace simulation {

/// @brief Nearest-hit ray casting against a scene through a bounding volume hierarchy.
///
/// Every polyline becomes tapered-cylinder segments plus spheres at its interior vertices
/// (closing the joints); wires are split into 1 m segments so their boxes stay small.
class RayCaster {
 public:
  /// @param scene the scene; copied into flat primitives, the scene can be discarded after
  explicit RayCaster(const Scene& scene);

  /// @brief Nearest hit with t in (t_min, t_max), or nothing.
  std::optional<Hit> cast(const Ray& ray, double t_min, double t_max) const;

  /// @brief Number of primitives in the hierarchy (ground excluded).
  std::size_t size() const { return prims_.size(); }

 private:
  struct Prim {
    bool is_sphere = false;
    Frustum frustum;
    Sphere sphere;
    Label label;
    float reflectivity = 0.0f;
  };
  struct Node {
    Eigen::Vector3d lo = Eigen::Vector3d::Zero();
    Eigen::Vector3d hi = Eigen::Vector3d::Zero();
    std::uint32_t first = 0;  // leaf: first primitive; inner: left child
    std::uint32_t count = 0;  // leaf: primitive count; inner: 0
    std::uint32_t right = 0;  // inner: right child
  };

  void addPolyline(const BranchPolyline& b, std::uint16_t object, std::uint16_t index, float refl);
  std::uint32_t build(std::uint32_t begin, std::uint32_t end, int depth);

  std::vector<Prim> prims_;
  std::vector<Eigen::Vector3d> prim_lo_;
  std::vector<Eigen::Vector3d> prim_hi_;
  std::vector<Node> nodes_;
  bool has_ground_;
  double ground_z_;
  double ground_half_extent_;
  float ground_reflectivity_;
};

}  // namespace simulation
}  // namespace dormant_tree_modeling
