#include "dormant_tree_modeling/ros/model_messages.h"

#include <Eigen/Geometry>
#include <cstdio>

namespace dormant_tree_modeling {
namespace ros_layer {

namespace {

dormant_tree_modeling::Cylinder cylinderMsg(const modeling::CylinderModel& c, std::uint8_t role,
                                            int parent) {
  dormant_tree_modeling::Cylinder m;
  m.role = role;
  m.id = static_cast<std::uint32_t>(c.id);
  m.parent_id = parent;
  m.center.x = c.center.x();
  m.center.y = c.center.y();
  m.center.z = c.center.z();
  m.axis.x = c.axis.x();
  m.axis.y = c.axis.y();
  m.axis.z = c.axis.z();
  m.radius = 0.5 * c.diameter;
  m.length = c.length;
  m.num_points = static_cast<std::uint32_t>(c.num_points);
  m.inlier_ratio = static_cast<float>(c.inlier_ratio);
  return m;
}

/// A marker to add, of a type, keyed by namespace and id.
visualization_msgs::Marker newMarker(const std_msgs::Header& header, const std::string& ns, int id,
                                     int type) {
  visualization_msgs::Marker m;
  m.header = header;
  m.ns = ns;
  m.id = id;
  m.type = type;
  m.action = visualization_msgs::Marker::ADD;
  return m;
}

visualization_msgs::Marker cylinderMarker(const modeling::CylinderModel& c,
                                          const std_msgs::Header& header, const std::string& ns,
                                          float r, float g, float b) {
  visualization_msgs::Marker m = newMarker(header, ns, c.id, visualization_msgs::Marker::CYLINDER);
  m.pose.position.x = c.center.x();
  m.pose.position.y = c.center.y();
  m.pose.position.z = c.center.z();
  // rviz cylinders stand along their z axis.
  const Eigen::Quaterniond q = Eigen::Quaterniond::FromTwoVectors(Eigen::Vector3d::UnitZ(), c.axis);
  m.pose.orientation.x = q.x();
  m.pose.orientation.y = q.y();
  m.pose.orientation.z = q.z();
  m.pose.orientation.w = q.w();
  m.scale.x = m.scale.y = std::max(1e-3, c.diameter);
  m.scale.z = std::max(1e-3, c.length);
  m.color.r = r;
  m.color.g = g;
  m.color.b = b;
  m.color.a = 0.85f;
  return m;
}

visualization_msgs::Marker label(const modeling::CylinderModel& c, const std_msgs::Header& header,
                                 const std::string& ns, const std::string& text) {
  visualization_msgs::Marker m =
      newMarker(header, ns, c.id, visualization_msgs::Marker::TEXT_VIEW_FACING);
  const Eigen::Vector3d p = c.center + 0.5 * c.length * c.axis;
  m.pose.position.x = p.x();
  m.pose.position.y = p.y();
  m.pose.position.z = p.z() + 0.03;
  m.pose.orientation.w = 1.0;
  m.scale.z = 0.04;
  m.color.r = m.color.g = m.color.b = 1.0f;
  m.color.a = 1.0f;
  m.text = text;
  return m;
}

/// A diameter in cm; a branch whose diameter was not measured shows the range it may have.
std::string diameterText(double diameter, const modeling::BranchMeasurement* branch = nullptr) {
  char text[48];
  if (branch && !branch->diameter_resolved)
    std::snprintf(text, sizeof(text), "%.1f-%.1f cm", 100.0 * branch->diameter_min,
                  100.0 * branch->diameter_max);
  else
    std::snprintf(text, sizeof(text), "%.1f cm", 100.0 * diameter);
  return text;
}

}  // namespace

dormant_tree_modeling::TreeModel toMsg(const modeling::TreeModel& model,
                                       const std_msgs::Header& header) {
  dormant_tree_modeling::TreeModel msg;
  msg.header = header;
  for (const auto& c : model.trunk)
    msg.trunk.push_back(cylinderMsg(c, dormant_tree_modeling::Cylinder::TRUNK, -1));
  for (const auto& b : model.primary_branches) {
    msg.primary_branches.push_back(
        cylinderMsg(b.cylinder, dormant_tree_modeling::Cylinder::PRIMARY_BRANCH, b.trunk_segment));
    dormant_tree_modeling::BranchMeasurement m;
    m.cylinder_id = static_cast<std::uint32_t>(b.cylinder.id);
    m.attachment_height = b.measurement.attachment_height;
    m.angle_to_trunk = b.measurement.angle_to_trunk;
    m.diameter = b.cylinder.diameter;
    m.trunk_diameter = b.measurement.trunk_diameter;
    m.diameter_ratio = b.measurement.diameter_ratio;
    m.prune = b.measurement.prune;
    m.diameter_resolved = b.measurement.diameter_resolved;
    m.diameter_min = b.measurement.diameter_min;
    m.diameter_max = b.measurement.diameter_max;
    msg.measurements.push_back(m);
  }
  msg.input_points = static_cast<std::uint32_t>(model.input_points);
  msg.processing_time = model.runtime_s;
  msg.calibration = model.correction.calibration;
  msg.calibration_hash = model.correction.calibration_hash;
  msg.noise_sigma = model.correction.noise_sigma;
  msg.warnings = model.correction.warnings;
  return msg;
}

visualization_msgs::MarkerArray toMarkers(const modeling::TreeModel& model,
                                          const std_msgs::Header& header) {
  visualization_msgs::MarkerArray array;
  visualization_msgs::Marker clear;
  clear.header = header;
  clear.action = visualization_msgs::Marker::DELETEALL;
  array.markers.push_back(clear);
  for (const auto& c : model.trunk) {
    array.markers.push_back(cylinderMarker(c, header, "trunk", 0.55f, 0.32f, 0.08f));
    array.markers.push_back(label(c, header, "trunk_labels", diameterText(c.diameter)));
  }
  for (const auto& b : model.primary_branches) {
    // Red: to prune; green: to keep; grey: its diameter was not measured (diameter_resolved).
    const bool prune = b.measurement.prune;
    float r = prune ? 0.9f : 0.1f, g = prune ? 0.1f : 0.75f, blue = 0.1f;
    if (!b.measurement.diameter_resolved)
      r = g = blue = 0.6f;
    array.markers.push_back(cylinderMarker(b.cylinder, header, "primary_branches", r, g, blue));
    array.markers.push_back(label(b.cylinder, header, "primary_branch_labels",
                                  diameterText(b.cylinder.diameter, &b.measurement)));
  }
  return array;
}

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
