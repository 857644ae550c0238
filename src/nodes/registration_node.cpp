#include "dormant_tree_modeling/ros/registration_node.h"
#include "dormant_tree_modeling/ros/node_support.h"

using dormant_tree_modeling::ros_layer::RegistrationNode;

int main(int argc, char** argv) {
  // Two threads: views keep arriving while a service call waits on tf.
  return dormant_tree_modeling::ros_layer::runNode<RegistrationNode>(argc, argv, "registration", 2);
}
