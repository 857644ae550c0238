#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/buffer.h>

#include <condition_variable>
#include <mutex>
#include <set>
#include <string>
#include <thread>

#include "dormant_tree_modeling/modeling/node_config.h"
#include "dormant_tree_modeling/modeling/tree_modeler.h"
#include "dormant_tree_modeling/ros/tf_feed.h"

#include "dormant_tree_modeling/ros/node_support.h"

namespace dormant_tree_modeling {
namespace ros_layer {

/// @brief ROS wrapper of the tree modeler.
///
/// Subscribes `tree_cloud` (sensor_msgs/PointCloud2); publishes, latched, `tree_model`
/// (dormant_tree_modeling/TreeModel), `markers` (visualization_msgs/MarkerArray: trunk brown,
/// primaries green, pruning candidates red, each labelled with its diameter in cm) and
/// `segments` (PointCloud2 of the modeled points with an `intensity` field: 0 other,
/// 1 trunk, 2 primary branch). Service `~model_tree` (std_srvs/Trigger) models the last cloud
/// again. Parameters: `~config_file` (YAML of ModelerConfig; empty: defaults); `~output_dir`
/// (optional: each model is also written there as model.json and cylinders.csv, in
/// `~output_frame` when set, e.g. `orchard`, through tf, else in the cloud's frame), with the
/// cloud it was made from as cloud.pcd and cloud.ply in the same frame.
/// Diagnostics: models made and failed, the last outcome, whether a cloud is being modeled.
/// Modeling runs on a worker thread; a cloud arriving while one is being modeled waits in a
/// single slot, replacing (with a warning) any cloud already waiting there.
/// With `~exit_after_models` N > 0 the node shuts down once N clouds have been modeled or have
/// failed (a replay that is to end, with `required` in its launch file).
class TreeModelerNode {
 public:
  /// @throws Error when the configuration cannot be loaded
  TreeModelerNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  /// @brief With the node's parameters already read.
  TreeModelerNode(ros::NodeHandle& nh, ros::NodeHandle& pnh,
                  const modeling::TreeModelerNodeConfig& node);
  ~TreeModelerNode();
  TreeModelerNode(const TreeModelerNode&) = delete;
  TreeModelerNode& operator=(const TreeModelerNode&) = delete;

  /// @brief The process's exit status: 0 when the last cloud was modeled (or none came), 1
  /// when it failed.
  int exitStatus();

 private:
  void cloudCallback(const sensor_msgs::PointCloud2ConstPtr& msg);
  bool modelTree(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  void enqueue(const sensor_msgs::PointCloud2ConstPtr& msg);
  void workerLoop();
  /// Models one cloud and publishes; returns a one-line summary or throws Error.
  std::string process(const sensor_msgs::PointCloud2& msg);
  /// Publishes the model, markers and segments (and writes the files); returns a summary.
  std::string publish(const modeling::ModelResult& result, const std_msgs::Header& header);
  void writeFiles(const modeling::ModelResult& result, const Cloud& cloud,
                  const std_msgs::Header& header);
  void noteOutcome(bool ok, const std::string& message);
  /// Logs each calibration warning of the models the first time it comes.
  void warnOnce(const std::vector<std::string>& warnings);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  modeling::TreeModeler modeler_;
  std::string output_dir_, output_frame_;
  tf2_ros::Buffer tf_buffer_{ros::Duration(TF_CACHE_S)};
  TfFeed tf_feed_{tf_buffer_};
  NodeDiagnostics diagnostics_;
  ros::Subscriber cloud_sub_;
  ros::Publisher model_pub_, marker_pub_, segments_pub_;
  ros::ServiceServer model_srv_;

  std::mutex mutex_;
  std::condition_variable wake_;
  sensor_msgs::PointCloud2ConstPtr pending_;  // waiting to be modeled
  sensor_msgs::PointCloud2ConstPtr last_;     // last cloud received, for ~model_tree
  bool stop_ = false;
  bool busy_ = false, last_ok_ = true;
  std::size_t models_ = 0, failures_ = 0;
  int exit_after_models_ = 0;  // 0: never
  std::string last_outcome_ = "no cloud yet";
  std::set<std::string> warned_;  // the models' calibration warnings logged so far
  std::thread worker_;
};

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
