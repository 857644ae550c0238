#include "dormant_tree_modeling/ros/stage_controller_node.h"
#include "dormant_tree_modeling/ros/node_support.h"

using dormant_tree_modeling::ros_layer::StageControllerNode;

int main(int argc, char** argv) {
  // Two threads: a waiting move must not hold up the home service or the diagnostics.
  // A home or move service call may be waiting on the controller: end it before the spinner
  // joins its thread.
  return dormant_tree_modeling::ros_layer::runNode<StageControllerNode>(
      argc, argv, "stage_controller", 2, [](StageControllerNode& node) {
        node.interrupt();
        return 0;
      });
}
