#include "dormant_tree_modeling/ros/acquisition_node.h"
#include "dormant_tree_modeling/ros/node_support.h"

using dormant_tree_modeling::ros_layer::AcquisitionNode;

int main(int argc, char** argv) {
  // Recording callbacks keep running while the operator is being waited for.
  return dormant_tree_modeling::ros_layer::runNode<AcquisitionNode>(argc, argv, "acquisition", 3);
}
