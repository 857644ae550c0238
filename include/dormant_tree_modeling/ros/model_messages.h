#pragma once

#include <dormant_tree_modeling/TreeModel.h>
#include <visualization_msgs/MarkerArray.h>

#include "dormant_tree_modeling/modeling/tree_model.h"

namespace dormant_tree_modeling {
namespace ros_layer {

/// @brief Core model -> TreeModel message (geometry in the header's frame).
dormant_tree_modeling::TreeModel toMsg(const modeling::TreeModel& model,
                                       const std_msgs::Header& header);

/// @brief rviz markers: a cylinder per trunk segment (brown) and primary branch (green; red
/// when flagged for pruning) and a text label with the diameter in cm; a DELETEALL first so
/// a new model replaces the old one.
visualization_msgs::MarkerArray toMarkers(const modeling::TreeModel& model,
                                          const std_msgs::Header& header);

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
