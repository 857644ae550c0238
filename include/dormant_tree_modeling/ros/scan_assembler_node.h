#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <sensor_msgs/JointState.h>
#include <sensor_msgs/LaserScan.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/buffer.h>

#include <condition_variable>
#include <deque>
#include <memory>
#include <mutex>
#include <thread>

#include "dormant_tree_modeling/acquisition/sweep_recorder.h"
#include "dormant_tree_modeling/acquisition/sweep_watcher.h"
#include "dormant_tree_modeling/acquisition/view_processing.h"
#include "dormant_tree_modeling/ros/tf_feed.h"

#include "dormant_tree_modeling/ros/node_support.h"

namespace dormant_tree_modeling {
namespace ros_layer {

/// @brief ROS wrapper of the scan assembler: one rotary sweep -> one view.
///
/// Subscribes `scan` (LaserScan of the LMS111 driver) and `joint_states` (the stage's); service
/// `~acquire_view` (std_srvs/Trigger) runs a sweep through the stage's `move_axis` service,
/// either continuous (the stage turns at one θ step per scan period while the laser streams:
/// 8 s at 25 Hz) or step-and-scan (`~mode: step`, the paper's: move, settle, take one line),
/// gives every beam the θ interpolated from the stamped stage positions, applies Eq. 1,
/// converts to the platform frame (tf) and isolates the target tree. Publishes `view_cloud`
/// (PointCloud2 in the platform frame, stamped at the sweep's middle, so the platform's pose
/// at that time in tf is the view's pose guess) and `range_image` (sensor_msgs/Image 32FC1,
/// m, a row per line). Parameters in config/scan_assembler.yaml.
///
/// With `~passive` (rosbag replay) it commands nothing: every continuous sweep seen in
/// `joint_states` (from before one end of the θ range past the other) becomes a view, assembled
/// on a worker thread from the same scans and positions, so a replay gives the views of the
/// live run. Diagnostics: scans and views, failures, the last view.
class ScanAssemblerNode {
 public:
  /// @throws Error INVALID_ARGUMENT for a bad parameter
  ScanAssemblerNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  ~ScanAssemblerNode();
  ScanAssemblerNode(const ScanAssemblerNode&) = delete;
  ScanAssemblerNode& operator=(const ScanAssemblerNode&) = delete;

 private:
  void scanCallback(const sensor_msgs::LaserScanConstPtr& msg);
  void jointCallback(const sensor_msgs::JointStateConstPtr& msg);
  bool acquireView(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  /// Runs the sweep; returns a summary or throws Error.
  std::string acquire();
  /// Processes one assembled sweep into a view and publishes it; returns a summary or throws.
  std::string publishView(acquisition::RangeImage image, std::size_t dropped, std::size_t missing,
                          const ros::WallTime& started);
  /// Passive mode: waits, however long, for a scan line stamped after `stamp`; false when the
  /// node shuts down first.
  bool awaitLineAfter(double stamp);
  /// The target trunk's base as the plan expects it in the platform frame: the origin of
  /// `~tree_frame` through tf when known, else `~tree_distance` straight ahead (z NaN).
  Eigen::Vector3d treeHint(const ros::Time& stamp);
  /// Passive mode: turns the watched sweeps into views.
  void passiveLoop();
  void noteOutcome(bool ok, const std::string& message);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);
  void moveRotary(double target_deg, double velocity_deg_s);
  double lastScanPeriod();

  std::string rotary_axis_, rotary_joint_, move_service_, platform_frame_, stage_frame_,
      tree_frame_;
  acquisition::SweepConfig sweep_;
  double tree_distance_, max_missing_rows_;
  acquisition::ViewProcessingConfig processing_;

  ros::NodeHandle nh_;
  ros::Subscriber scan_sub_, joint_sub_;
  ros::Publisher cloud_pub_, image_pub_;
  ros::ServiceServer acquire_srv_;
  tf2_ros::Buffer tf_buffer_{ros::Duration(TF_CACHE_S)};
  TfFeed tf_feed_{tf_buffer_};

  std::unique_ptr<acquisition::SweepRecorder> recorder_;  // scans and stage positions
  std::mutex acquire_mutex_;                              // one sweep at a time
  NodeDiagnostics diagnostics_;

  bool passive_ = false;
  std::unique_ptr<acquisition::SweepWatcher> watcher_;  // passive: sweeps in joint_states
  std::mutex state_mutex_;
  std::condition_variable wake_;
  std::deque<acquisition::WatchedSweep> sweeps_;  // passive: waiting to be assembled
  bool stop_ = false;
  std::size_t scans_ = 0, views_ = 0, failures_ = 0;
  double last_scan_wall_ = 0.0;
  std::string last_outcome_ = "no view yet";
  bool last_ok_ = true;
  std::thread worker_;
};

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
