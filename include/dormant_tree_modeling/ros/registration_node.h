#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>
#include <sensor_msgs/PointCloud2.h>
#include <std_msgs/String.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/buffer.h>
#include <tf2_ros/static_transform_broadcaster.h>
#include <topic_tools/shape_shifter.h>

#include <mutex>
#include <optional>
#include <string>
#include <thread>
#include <vector>

#include "dormant_tree_modeling/common/cloud.h"
#include "dormant_tree_modeling/registration/multi_view.h"
#include "dormant_tree_modeling/registration/node_config.h"
#include "dormant_tree_modeling/registration/stations.h"
#include "dormant_tree_modeling/registration/view_folder.h"
#include "dormant_tree_modeling/ros/tf_feed.h"

#include "dormant_tree_modeling/ros/node_support.h"

namespace dormant_tree_modeling {
namespace ros_layer {

/// @brief A plan's end as the acquisition reports it.
struct PlanEnd {
  std::optional<int> views;  ///< the views it says were acquired, when it says
};

/// @brief The plan's end in a progress message: the typed AcquisitionProgress in state
/// FINISHED, or the text "finished: N of M planned views acquired, ..." of bags recorded
/// before the progress was typed. None for any other progress or type.
std::optional<PlanEnd> planEnd(const topic_tools::ShapeShifter& msg);

/// @brief ROS wrapper of the multi-view registration.
///
/// Collects `view_cloud`s (PointCloud2, in the platform frame as the scan assembler
/// publishes them). A view's station is its platform position: views whose `orchard` ->
/// platform transform (the plan's or the operator's estimate, used only as a hint) did not
/// change belong to one station; without that transform every view is its own station.
/// Registers on `~register` (std_srvs/Trigger), when `~expected_views` have arrived, or when
/// the acquisition reports FINISHED on `~plan_progress_topic` (AcquisitionProgress; the text
/// "finished: ..." of older bags is read too), on a worker thread. A
/// "finished" that names more views than have arrived (a replay: the scan assembler is still
/// assembling the last sweeps) waits up to `~finished_wait` wall-clock seconds for them.
/// Publishes, latched, `~tree_cloud` (the registered views, frame `~tree_frame` = the first
/// registered view's platform frame), `~view_poses` (geometry_msgs/PoseArray in that frame, one
/// per input view, registered or not) and `~report` (std_msgs/String, the Markdown report), and
/// the static tf `orchard` -> tree frame (from the first station's hint) and tree frame ->
/// `view_<i>`. Writes registered.pcd/.ply, registration.json and registration.md to a folder
/// per registration under `~output_dir`. `~reset` drops the views collected so far.
/// Diagnostics: views collected, stations, the last registration's outcome.
class RegistrationNode {
 public:
  /// @throws Error when the configuration cannot be loaded
  RegistrationNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  /// @brief With the node's parameters already read.
  RegistrationNode(ros::NodeHandle& nh, ros::NodeHandle& pnh,
                   const registration::RegistrationNodeConfig& node);
  ~RegistrationNode();
  RegistrationNode(const RegistrationNode&) = delete;
  RegistrationNode& operator=(const RegistrationNode&) = delete;

 private:
  void viewCallback(const sensor_msgs::PointCloud2ConstPtr& msg);
  void progressCallback(const topic_tools::ShapeShifter::ConstPtr& msg);
  /// The plan's end named views that have not arrived within `~finished_wait`.
  void finishedWaitExpired();
  void checkEndOfInput();
  bool registerService(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool resetService(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  /// Starts a registration of the collected views on the worker; false (and why) when busy
  /// or when nothing was collected.
  /// @param ended_by what started it, @param planned the views the plan named (see
  /// registration::RegistrationInput)
  bool startRegistration(std::string& why, registration::RegistrationInput::End ended_by,
                         std::optional<int> planned = std::nullopt);
  void run(std::vector<registration::ViewInput> views, ros::Time stamp,
           registration::RegistrationInput input);
  void publish(const Cloud& registered, const std::vector<registration::ViewInput>& views,
               const registration::RegistrationResult& result, const ros::Time& stamp);
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  registration::RegistrationConfig config_;
  ros::NodeHandle nh_;
  std::string orchard_frame_, tree_frame_, laser_frame_, output_dir_;
  int expected_views_ = 0;
  double hint_timeout_ = 0.5;
  double finished_wait_ = 10.0;

  tf2_ros::Buffer tf_buffer_{ros::Duration(TF_CACHE_S)};
  TfFeed tf_feed_{tf_buffer_};
  tf2_ros::StaticTransformBroadcaster static_tf_;
  ros::Subscriber view_sub_, progress_sub_;
  ros::Publisher cloud_pub_, poses_pub_, report_pub_;
  ros::ServiceServer register_srv_, reset_srv_;
  NodeDiagnostics diagnostics_;
  ros::WallTimer finished_timer_, input_timer_;
  double end_of_input_timeout_ = 0.0;  // s without a message on input_sub_'s topic; 0 off
  ros::Subscriber input_sub_;
  ros::WallTime last_input_;

  std::mutex mutex_;
  std::vector<registration::ViewInput> views_;
  registration::StationGrouper stations_;
  ros::Time last_stamp_;
  /// Set between a plan's end and the arrival of the views it names.
  std::optional<int> awaited_views_;
  bool busy_ = false;
  std::string last_outcome_ = "no registration yet";
  bool last_ok_ = true;
  std::thread worker_;
};

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
