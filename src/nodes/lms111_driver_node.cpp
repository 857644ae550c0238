#include "dormant_tree_modeling/ros/lms111_driver_node.h"
#include "dormant_tree_modeling/ros/node_support.h"

using dormant_tree_modeling::ros_layer::Lms111DriverNode;

int main(int argc, char** argv) {
  return dormant_tree_modeling::ros_layer::runNode<Lms111DriverNode>(argc, argv, "lms111_driver",
                                                                     1);
}
