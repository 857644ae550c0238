#include "dormant_tree_modeling/ros/cloud_file_publisher.h"
#include "dormant_tree_modeling/ros/node_support.h"

using dormant_tree_modeling::ros_layer::CloudFilePublisher;

int main(int argc, char** argv) {
  return dormant_tree_modeling::ros_layer::runNode<CloudFilePublisher>(argc, argv,
                                                                       "cloud_file_publisher", 1);
}
