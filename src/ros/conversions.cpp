#include "dormant_tree_modeling/ros/conversions.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <sensor_msgs/point_cloud2_iterator.h>

#include <cmath>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace ros_layer {

sensor_msgs::PointCloud2 toMsg(const Cloud& cloud, const std::string& frame_id,
                               const ros::Time& stamp) {
  sensor_msgs::PointCloud2 msg;
  msg.header.frame_id = frame_id;
  msg.header.stamp = stamp;
  sensor_msgs::PointCloud2Modifier modifier(msg);
  modifier.setPointCloud2FieldsByString(1, "xyz");
  modifier.resize(cloud.size());
  sensor_msgs::PointCloud2Iterator<float> x(msg, "x"), y(msg, "y"), z(msg, "z");
  for (const auto& p : cloud.points) {
    *x = p.x;
    *y = p.y;
    *z = p.z;
    ++x;
    ++y;
    ++z;
  }
  msg.is_dense = true;
  return msg;
}

CloudPtr fromMsg(const sensor_msgs::PointCloud2& msg, std::size_t* dropped_non_finite) {
  bool has[3] = {false, false, false};
  const char* names[3] = {"x", "y", "z"};
  for (const auto& f : msg.fields) {
    for (int i = 0; i < 3; ++i) {
      if (f.name == names[i]) {
        if (f.datatype != sensor_msgs::PointField::FLOAT32) {
          throw Error(ErrorCode::PARSE_ERROR,
                      std::string("PointCloud2 field '") + names[i] + "' is not float32");
        }
        has[i] = true;
      }
    }
  }
  if (!has[0] || !has[1] || !has[2]) {
    throw Error(ErrorCode::PARSE_ERROR, "PointCloud2 has no x/y/z fields");
  }
  const std::size_t n = static_cast<std::size_t>(msg.width) * msg.height;
  if (msg.data.size() < n * msg.point_step) {
    throw Error(ErrorCode::PARSE_ERROR, "PointCloud2 data is shorter than width*height*point_step");
  }
  auto cloud = std::make_shared<Cloud>();
  cloud->reserve(n);
  std::size_t dropped = 0;
  sensor_msgs::PointCloud2ConstIterator<float> x(msg, "x"), y(msg, "y"), z(msg, "z");
  for (std::size_t i = 0; i < n; ++i, ++x, ++y, ++z) {
    if (std::isfinite(*x) && std::isfinite(*y) && std::isfinite(*z)) {
      cloud->push_back(pcl::PointXYZ(*x, *y, *z));
    } else {
      ++dropped;
    }
  }
  if (dropped_non_finite)
    *dropped_non_finite = dropped;
  return cloud;
}

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
