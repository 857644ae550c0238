#pragma once
// A synthetic tree cloud for node tests: 8 views of the plan of one seeded orchard, cropped to
// the target tree as the registration would publish it.
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <sensor_msgs/PointCloud2.h>
#include <unistd.h>

#include <filesystem>
#include <string>

#include "dormant_tree_modeling/io/point_cloud_io.h"
#include "dormant_tree_modeling/ros/conversions.h"
#include "dormant_tree_modeling/simulation/dataset.h"

namespace dormant_tree_modeling {
namespace test {

inline sensor_msgs::PointCloud2 syntheticTree(const std::string& frame_id) {
  const auto dir =
      std::filesystem::temp_directory_path() / ("dtm_rostest_" + std::to_string(getpid()));
  simulation::DatasetConfig o;
  o.seed = 3;
  o.sensor.range_noise_sigma = 0.006;
  o.plan.heights_m = {1.5, 3.0};
  o.plan.positions_per_height = 1;
  o.plan.slide_steps = 2;
  o.plan.slide_step_m = 0.2;
  o.write_views = false;
  simulation::writeDataset(o, dir.string());
  const auto cloud = io::readCloud((dir / "target.pcd").string());
  std::filesystem::remove_all(dir);
  return ros_layer::toMsg(*cloud.cloud, frame_id, ros::Time::now());
}

}  // namespace test
}  // namespace dormant_tree_modeling
