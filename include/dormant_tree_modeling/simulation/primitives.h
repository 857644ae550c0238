#pragma once

#include <Eigen/Core>
#include <cstdint>
#include <optional>

namespace dormant_tree_modeling {
namespace simulation {

/// @brief What a surface belongs to; carried by every simulated return as its true label.
enum class Part : std::uint8_t {
  TRUNK = 0,
  PRIMARY = 1,    ///< primary branch (attached to the trunk)
  SECONDARY = 2,  ///< shoots and spurs on primaries
  MINOR = 3,      ///< thin or short shoots on the trunk
  WIRE = 4,
  POST = 5,
  GROUND = 6,
  NONE = 255,
};

/// @brief Object and part of a surface. object 0 is the target tree.
struct Label {
  std::uint16_t object = 0;
  Part part = Part::NONE;
  std::uint16_t branch = 0;  ///< index of the polyline within its object
};

/// @brief A ray o + t d with |d| = 1.
struct Ray {
  Eigen::Vector3d origin = Eigen::Vector3d::Zero();
  Eigen::Vector3d direction = Eigen::Vector3d::UnitX();
};

/// @brief The nearest intersection of a ray with a surface.
struct Hit {
  double t = 0.0;                                     ///< distance along the ray, m
  Eigen::Vector3d normal = Eigen::Vector3d::UnitZ();  ///< unit surface normal
  Label label;
  float reflectivity = 0.0f;  ///< diffuse reflectance of the surface, 0..1
};

/// @brief Truncated cone (tapered cylinder) from a (radius ra) to b (radius rb); ra = rb gives a
/// cylinder, ra or rb = 0 a cone. Open at both ends: joints are closed with spheres.
struct Frustum {
  Eigen::Vector3d a = Eigen::Vector3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  double ra = 0.0;
  double rb = 0.0;
};

/// @brief Sphere of radius r at c.
struct Sphere {
  Eigen::Vector3d c = Eigen::Vector3d::Zero();
  double r = 0.0;
};

/// @brief Nearest t in (t_min, t_max) where the ray meets the frustum's side, with its normal.
std::optional<std::pair<double, Eigen::Vector3d>> intersect(const Ray& ray, const Frustum& f,
                                                            double t_min, double t_max);

/// @brief Nearest t in (t_min, t_max) where the ray meets the sphere, with its normal.
std::optional<std::pair<double, Eigen::Vector3d>> intersect(const Ray& ray, const Sphere& s,
                                                            double t_min, double t_max);

}  // namespace simulation
}  // namespace dormant_tree_modeling
