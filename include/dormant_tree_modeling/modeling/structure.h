#pragma once

#include <cstddef>

#include "dormant_tree_modeling/modeling/geometry_fit.h"

namespace dormant_tree_modeling {
namespace modeling {

class PointIndex;

/// @brief How the number of neighbours grows with the radius: log2 of the neighbours within
/// 2 r over those within r, summed over a sample of the points.
///
/// Scanned surfaces give about 2 (a trunk's bark, the ground), thin branches and wires about
/// 1 at radii above the range noise, points that fill a volume about 3: a cloud with no
/// surfaces to model (sensor noise, a scene of dust or rain) is told from a tree before the
/// search, whose cost grows with the number of clusters such a cloud forms.
/// @param pts the points
/// @param index an index of pts
/// @param radius_m r, above the range noise so that a noisy surface still reads as one
/// @param samples points sampled (evenly through pts)
/// @returns the dimension, or 0 when no sampled point has a neighbour within r
double neighbourGrowthDimension(const Points& pts, const PointIndex& index, double radius_m,
                                std::size_t samples);

}  // namespace modeling
}  // namespace dormant_tree_modeling
