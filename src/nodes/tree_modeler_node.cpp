#include "dormant_tree_modeling/ros/tree_modeler_node.h"
#include "dormant_tree_modeling/ros/node_support.h"

using dormant_tree_modeling::ros_layer::TreeModelerNode;

int main(int argc, char** argv) {
  // Two threads: the service can model on demand while the subscriber keeps queueing.
  return dormant_tree_modeling::ros_layer::runNode<TreeModelerNode>(
      argc, argv, "tree_modeler", 2, [](TreeModelerNode& node) { return node.exitStatus(); });
}
