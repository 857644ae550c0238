#pragma once

#include <Eigen/Core>
#include <cstddef>
#include <vector>

namespace dormant_tree_modeling {

/// @brief The median of the values (the upper one of the two middle values for an even
/// count), 0 for none. Takes the values by copy: it reorders them.
double median(std::vector<double> values);

/// @brief The value of rank floor(q (n - 1)) among the values, 0 <= q <= 1; 0 for none.
/// Reorders them (nth_element), so that several quantiles of one sample cost little.
double quantileInPlace(std::vector<double>& values, double q);

/// @brief The standard deviation of a normal sample from its absolute deviations (from its
/// centre, a fit, or a neighbour): 1.4826 x their median, which outliers cannot move; 0 for
/// none. Takes the values by copy: it reorders them.
double sigmaFromAbsoluteDeviations(std::vector<double> abs_deviations);

/// @brief One coordinate (0 x, 1 y, 2 z) of every (n / max_samples)-th point: a sample whose
/// quantiles one stray point cannot move and whose size stays near max_samples.
std::vector<double> axisSample(const std::vector<Eigen::Vector3d>& points, int axis,
                               std::size_t max_samples);

}  // namespace dormant_tree_modeling
