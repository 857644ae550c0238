#include "dormant_tree_modeling/ros/scan_assembler_node.h"
#include "dormant_tree_modeling/ros/node_support.h"

using dormant_tree_modeling::ros_layer::ScanAssemblerNode;

int main(int argc, char** argv) {
  // A sweep blocks its service call for seconds while scans and joint states keep coming.
  return dormant_tree_modeling::ros_layer::runNode<ScanAssemblerNode>(argc, argv, "scan_assembler",
                                                                      3);
}
