#pragma once

#include <Eigen/Core>
#include <vector>

namespace dormant_tree_modeling {
namespace evaluation {

/// @brief A centreline with a diameter at each vertex (m).
struct Polyline {
  int id = -1;                          ///< branch id; -1 for the trunk
  std::vector<Eigen::Vector3d> points;  ///< from the base outwards (trunk: ground upwards)
  std::vector<double> diameters;        ///< diameters[k] at points[k]
};

/// @brief Ground truth of one tree (docs/evaluation.md "truth.json").
struct GroundTruth {
  Polyline trunk;
  std::vector<Polyline> primary_branches;  ///< base diameter >= 0.8 cm and length >= 0.2 m
  std::vector<Polyline> minor_branches;    ///< thinner or shorter shoots on the trunk
};

}  // namespace evaluation
}  // namespace dormant_tree_modeling
