#pragma once

#include <vector>

namespace dormant_tree_modeling {

/// @brief The median of the values (the upper one of the two middle values for an even
/// count), 0 for none. Takes the values by copy: it reorders them.
double median(std::vector<double> values);

}  // namespace dormant_tree_modeling
