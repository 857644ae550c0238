#include "dormant_tree_modeling/ros/virtual_platform_node.h"
#include "dormant_tree_modeling/ros/node_support.h"

using dormant_tree_modeling::ros_layer::VirtualPlatformNode;

int main(int argc, char** argv) {
  // Two threads: answering the acquisition's prompt calls its service from a callback.
  return dormant_tree_modeling::ros_layer::runNode<VirtualPlatformNode>(argc, argv,
                                                                        "virtual_platform", 2);
}
