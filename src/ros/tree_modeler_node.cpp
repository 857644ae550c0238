#include "dormant_tree_modeling/ros/tree_modeler_node.h"

#include <dormant_tree_modeling/TreeModel.h>
#include <pcl/common/transforms.h>
#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <sensor_msgs/point_cloud2_iterator.h>
#include <tf2_eigen/tf2_eigen.h>
#include <visualization_msgs/MarkerArray.h>

#include <filesystem>
#include <sstream>

#include "dormant_tree_modeling/common/config_table.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/io/cylinder_csv.h"
#include "dormant_tree_modeling/io/point_cloud_io.h"
#include "dormant_tree_modeling/io/tree_json.h"
#include "dormant_tree_modeling/modeling/node_config.h"
#include "dormant_tree_modeling/ros/conversions.h"
#include "dormant_tree_modeling/ros/model_messages.h"
#include "dormant_tree_modeling/ros/node_support.h"
#include "dormant_tree_modeling/ros/tf_feed.h"

namespace dormant_tree_modeling {
namespace ros_layer {

namespace {

/// The modeler's parameters and sensor calibration from the files the node's parameters name.
modeling::ModelerConfig loadConfig(const modeling::TreeModelerNodeConfig& node) {
  modeling::treeModelerNodeConfigTable().check(node);
  modeling::ModelerConfig config;
  if (node.config_file.empty()) {
    ROS_WARN(
        "~config_file not set: using the built-in defaults (config/tree_modeler.yaml holds them "
        "too)");
  } else {
    config = modeling::loadModelerConfig(node.config_file);
  }
  if (node.calibration_file.empty()) {
    ROS_WARN(
        "~calibration_file not set: diameters are corrected for range noise only, not for the "
        "scanner's beam footprint (make a calibration with calibrate_diameters)");
    return config;
  }
  config.calibration = modeling::loadSensorCalibration(node.calibration_file);
  ROS_INFO("tree_modeler: sensor calibration '%s' (%s) from %s", config.calibration.name.c_str(),
           config.calibration.hash.c_str(), node.calibration_file.c_str());
  return config;
}

sensor_msgs::PointCloud2 segmentsMsg(const modeling::ModelResult& result,
                                     const std_msgs::Header& header) {
  sensor_msgs::PointCloud2 msg;
  msg.header = header;
  sensor_msgs::PointCloud2Modifier modifier(msg);
  modifier.setPointCloud2Fields(
      4, "x", 1, sensor_msgs::PointField::FLOAT32, "y", 1, sensor_msgs::PointField::FLOAT32, "z", 1,
      sensor_msgs::PointField::FLOAT32, "intensity", 1, sensor_msgs::PointField::FLOAT32);
  modifier.resize(result.points.size());
  sensor_msgs::PointCloud2Iterator<float> x(msg, "x"), y(msg, "y"), z(msg, "z"),
      label(msg, "intensity");
  for (std::size_t i = 0; i < result.points.size(); ++i, ++x, ++y, ++z, ++label) {
    *x = static_cast<float>(result.points[i].x());
    *y = static_cast<float>(result.points[i].y());
    *z = static_cast<float>(result.points[i].z());
    *label = static_cast<float>(result.classes[i]);
  }
  msg.is_dense = true;
  return msg;
}

}  // namespace

TreeModelerNode::TreeModelerNode(ros::NodeHandle& nh, ros::NodeHandle& pnh)
    : TreeModelerNode(nh, pnh, readParameters(pnh, modeling::treeModelerNodeConfigTable())) {}

TreeModelerNode::TreeModelerNode(ros::NodeHandle& nh, ros::NodeHandle& pnh,
                                 const modeling::TreeModelerNodeConfig& node)
    : modeler_(loadConfig(node)) {
  output_dir_ = node.output_dir;
  output_frame_ = node.output_frame;
  exit_after_models_ = node.exit_after_models;
  if (!output_dir_.empty())
    std::filesystem::create_directories(output_dir_);
  diagnostics_.add("tree modeler", this, &TreeModelerNode::diagnose);
  diagnostics_.start(nh, "none");
  model_pub_ = nh.advertise<dormant_tree_modeling::TreeModel>("tree_model", 1, true);
  marker_pub_ = nh.advertise<visualization_msgs::MarkerArray>("markers", 1, true);
  segments_pub_ = nh.advertise<sensor_msgs::PointCloud2>("segments", 1, true);
  worker_ = std::thread(&TreeModelerNode::workerLoop, this);
  cloud_sub_ = nh.subscribe("tree_cloud", 1, &TreeModelerNode::cloudCallback, this);
  model_srv_ = pnh.advertiseService("model_tree", &TreeModelerNode::modelTree, this);
  ROS_INFO("tree_modeler: waiting for clouds on %s", cloud_sub_.getTopic().c_str());
}

TreeModelerNode::~TreeModelerNode() {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    stop_ = true;
  }
  wake_.notify_all();
  if (worker_.joinable())
    worker_.join();
}

void TreeModelerNode::cloudCallback(const sensor_msgs::PointCloud2ConstPtr& msg) {
  enqueue(msg);
}

void TreeModelerNode::enqueue(const sensor_msgs::PointCloud2ConstPtr& msg) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    last_ = msg;
    if (pending_) {
      ROS_WARN(
          "tree_modeler: still modeling; the waiting cloud (stamp %.3f) is replaced by a newer one",
          pending_->header.stamp.toSec());
    }
    pending_ = msg;
  }
  wake_.notify_one();
}

bool TreeModelerNode::modelTree(std_srvs::Trigger::Request&, std_srvs::Trigger::Response& res) {
  sensor_msgs::PointCloud2ConstPtr cloud;
  {
    std::lock_guard<std::mutex> lock(mutex_);
    cloud = last_;
  }
  if (!cloud) {
    res.success = false;
    res.message = "no cloud received yet on " + cloud_sub_.getTopic();
    return true;
  }
  // Runs here, on the service's thread; the subscriber keeps queueing to the worker.
  try {
    res.message = process(*cloud);
    res.success = true;
  } catch (const std::exception& e) {
    res.success = false;
    res.message = e.what();
  }
  return true;
}

void TreeModelerNode::workerLoop() {
  for (;;) {
    sensor_msgs::PointCloud2ConstPtr cloud;
    {
      std::unique_lock<std::mutex> lock(mutex_);
      wake_.wait(lock, [this] { return stop_ || pending_; });
      if (stop_)
        return;
      cloud = pending_;
      pending_.reset();
    }
    try {
      ROS_INFO("tree_modeler: %s", process(*cloud).c_str());
    } catch (const Error& e) {
      ROS_ERROR("tree_modeler: %s: %s", errorCodeName(e.code()), e.what());
    } catch (const std::exception& e) {
      ROS_ERROR("tree_modeler: %s", e.what());
    }
  }
}

std::string TreeModelerNode::process(const sensor_msgs::PointCloud2& msg) {
  {
    std::lock_guard<std::mutex> lock(mutex_);
    busy_ = true;
  }
  try {
    std::size_t dropped = 0;
    const CloudPtr cloud = fromMsg(msg, &dropped);
    if (dropped > 0)
      ROS_WARN("tree_modeler: dropped %zu NaN/Inf points", dropped);
    const modeling::ModelResult result = modeler_.model(*cloud);
    for (const auto& notice : result.notices)
      ROS_WARN("tree_modeler: %s", notice.c_str());
    warnOnce(result.model.correction.warnings);
    const std::string summary = publish(result, msg.header);
    if (!output_dir_.empty())
      writeFiles(result, *cloud, msg.header);
    noteOutcome(true, summary);
    return summary;
  } catch (const Error& e) {
    noteOutcome(false, std::string(errorCodeName(e.code())) + ": " + e.what());
    throw;
  } catch (const std::exception& e) {
    noteOutcome(false, e.what());
    throw;
  }
}

void TreeModelerNode::warnOnce(const std::vector<std::string>& warnings) {
  std::lock_guard<std::mutex> lock(mutex_);
  for (const auto& w : warnings) {
    if (warned_.insert(w).second)
      ROS_WARN("tree_modeler: %s", w.c_str());
  }
}

std::string TreeModelerNode::publish(const modeling::ModelResult& result,
                                     const std_msgs::Header& header) {
  model_pub_.publish(toMsg(result.model, header));
  marker_pub_.publish(toMarkers(result.model, header));
  segments_pub_.publish(segmentsMsg(result, header));
  std::size_t prune = 0;
  for (const auto& b : result.model.primary_branches)
    prune += b.measurement.prune;
  std::ostringstream s;
  s << result.model.trunk.size() << " trunk cylinders, " << result.model.primary_branches.size()
    << " primary branches (" << prune << " to prune) from " << result.model.input_points
    << " points in " << result.model.runtime_s << " s";
  return s.str();
}

void TreeModelerNode::writeFiles(const modeling::ModelResult& result, const Cloud& cloud,
                                 const std_msgs::Header& header) {
  const modeling::TreeModel& model = result.model;
  modeling::TreeModel out = model;
  Eigen::Isometry3d to_output = Eigen::Isometry3d::Identity();
  if (!output_frame_.empty() && output_frame_ != header.frame_id) {
    try {
      to_output = tf2::transformToEigen(
          lookupWithin(tf_buffer_, output_frame_, header.frame_id, header.stamp, 2.0));
      out = modeling::transformModel(model, to_output);
    } catch (const tf2::TransformException& e) {
      throw Error(ErrorCode::IO_FAILURE, "the model was published but not written: no transform " +
                                             output_frame_ + " <- " + header.frame_id + ": " +
                                             e.what());
    }
  }
  io::writeTextFile(output_dir_ + "/model.json", io::modelToJson(out));
  io::writeTextFile(output_dir_ + "/cylinders.csv", io::cylindersToCsv(out));
  std::vector<modeling::RejectedBranch> turned_down = result.rejected_branches;
  for (auto& r : turned_down)
    r.centroid = to_output * r.centroid;
  io::writeTextFile(output_dir_ + "/turned_down.csv", io::turnedDownToCsv(turned_down));
  // The cloud beside the model, in the same frame, for pictures and for checking the fit.
  Cloud moved;
  pcl::transformPointCloud(cloud, moved, to_output.cast<float>().matrix());
  io::writeCloud(output_dir_ + "/cloud.pcd", moved);
  io::writeCloud(output_dir_ + "/cloud.ply", moved);
}

void TreeModelerNode::noteOutcome(bool ok, const std::string& message) {
  std::lock_guard<std::mutex> lock(mutex_);
  busy_ = false;
  (ok ? models_ : failures_) += 1;
  last_ok_ = ok;
  last_outcome_ = message;
  if (exit_after_models_ > 0 &&
      models_ + failures_ >= static_cast<std::size_t>(exit_after_models_)) {
    ROS_INFO("tree_modeler: %zu of %d clouds modeled (%zu failed): exiting (~exit_after_models)",
             models_ + failures_, exit_after_models_, failures_);
    ros::requestShutdown();
  }
}

int TreeModelerNode::exitStatus() {
  std::lock_guard<std::mutex> lock(mutex_);
  return last_ok_ ? 0 : 1;
}

void TreeModelerNode::diagnose(diagnostic_updater::DiagnosticStatusWrapper& status) {
  using diagnostic_msgs::DiagnosticStatus;
  std::lock_guard<std::mutex> lock(mutex_);
  status.add("models", models_);
  status.add("failures", failures_);
  status.add("modeling now", busy_);
  status.add("cloud waiting", static_cast<bool>(pending_));
  status.add("last outcome", last_outcome_);
  if (!output_dir_.empty())
    status.add("output", output_dir_);
  if (!last_ok_)
    status.summary(DiagnosticStatus::ERROR, "last cloud failed: " + last_outcome_);
  else
    status.summary(DiagnosticStatus::OK, busy_ ? "modeling" : last_outcome_);
}

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
