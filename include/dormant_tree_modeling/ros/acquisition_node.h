#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <dormant_tree_modeling/AcquisitionProgress.h>
#include <geometry_msgs/TransformStamped.h>
#include <ros/ros.h>
#include <rosbag/bag.h>
#include <std_srvs/Trigger.h>
#include <tf2_ros/transform_broadcaster.h>
#include <topic_tools/shape_shifter.h>

#include <atomic>
#include <condition_variable>
#include <mutex>
#include <optional>
#include <thread>

#include "dormant_tree_modeling/acquisition/sequencer.h"

#include "dormant_tree_modeling/ros/node_support.h"

namespace dormant_tree_modeling {
namespace ros_layer {

/// @brief The acquisition sequencer: runs the view plan of Algorithm 1 (config/view_plan.yaml)
/// through the stage's `move_axis` (slide) and the assembler's `acquire_view`, asks the
/// operator to move the platform (`~prompt`, std_msgs/String, latched; answered with
/// `~platform_in_place`, std_srvs/Trigger, by the rviz user or a script), publishes the plan's
/// platform pose as the tf `orchard -> platform` guess (and, before the move, as the goal
/// `~platform_goal`, geometry_msgs/PoseStamped, for a driver or the virtual platform's
/// operator), shows progress on `~progress` (AcquisitionProgress, latched: state, view, views
/// done, failed and planned, time left, the operator's line), and records the raw topics of the
/// tree into one rosbag (`~output_dir`/`~tree_name`.bag) with a Markdown report beside it. Services
/// `~start` and `~cancel`; a cancelled or interrupted run closes the bag, so it stays usable.
/// The final FINISHED progress goes into the bag too, so a replay knows the plan ended.
/// Diagnostics: state, views done and failed, the bag, the last problem.
class AcquisitionNode {
 public:
  /// @throws Error for a bad parameter or plan file
  AcquisitionNode(ros::NodeHandle& nh, ros::NodeHandle& pnh);
  ~AcquisitionNode();
  AcquisitionNode(const AcquisitionNode&) = delete;
  AcquisitionNode& operator=(const AcquisitionNode&) = delete;

 private:
  bool start(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool cancel(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  bool platformInPlace(std_srvs::Trigger::Request& req, std_srvs::Trigger::Response& res);
  void run();
  bool askForPlatform(const acquisition::PlannedView& view);
  /// Opens the tree's bag; false (said on ~progress and in the diagnostics) when it cannot.
  bool openBag(const std::string& bag_path, int planned);
  /// The sequencer's steps through the stage's and the assembler's services.
  acquisition::SequencerActions sequencerActions();
  /// Moves the slide; waits up to ~service_wait for a stage that is still setting up.
  void moveSlide(double slide);
  /// Sweeps and assembles one view; returns the assembler's summary.
  std::string acquireView();
  /// Closes the bag with the plan's end in it, writes the report, then announces the end.
  void finishRun(const std::vector<acquisition::ViewOutcome>& outcomes, int planned,
                 const std::string& bag_path);
  void record(const std::string& topic, const topic_tools::ShapeShifter::ConstPtr& msg);
  void publish(ros::Publisher& pub, const std::string& text);
  static dormant_tree_modeling::AcquisitionProgress progressMessage(
      std::uint8_t state, const acquisition::SequencerProgress& p, const std::string& text);
  void publishProgress(std::uint8_t state, const acquisition::SequencerProgress& p,
                       const std::string& text);
  /// Sends the platform's pose again, stamped now, so that tf has it at every view's time.
  void republishPlatform();
  void diagnose(diagnostic_updater::DiagnosticStatusWrapper& status);

  ros::NodeHandle nh_;
  acquisition::ViewPlanConfig plan_;
  std::string output_dir_, tree_name_, move_service_, acquire_service_, slide_axis_;
  std::string orchard_frame_, platform_frame_;
  std::vector<std::string> topics_;
  double slide_centre_, slide_velocity_;  // m, m/s (0: the stage's default)
  int max_retries_;
  double drain_s_;         // wait for in-flight messages before the bag closes
  double service_wait_s_;  // for the stage's and the assembler's services (start-up)

  ros::Publisher prompt_pub_, progress_pub_, goal_pub_;
  NodeDiagnostics diagnostics_;
  ros::ServiceServer start_srv_, cancel_srv_, in_place_srv_;
  std::vector<ros::Subscriber> recorders_;
  /// The plan's pose of the platform, `orchard` -> platform, republished on /tf (not
  /// /tf_static): a view is looked up at its own time, so a replay that delivers the next
  /// position's pose early does not move the views before it.
  tf2_ros::TransformBroadcaster platform_tf_pub_;
  std::optional<geometry_msgs::TransformStamped> platform_tf_;
  ros::Timer platform_tf_timer_;

  std::mutex bag_mutex_;
  rosbag::Bag bag_;
  bool recording_ = false;

  std::mutex mutex_;
  std::condition_variable wake_;
  bool in_place_ = false;
  std::string state_ = "idle", last_problem_;
  int done_ = 0, failed_ = 0, total_ = 0;
  acquisition::SequencerProgress last_progress_;  // the run's latest, on its thread only
  std::atomic<bool> cancel_{false}, running_{false};
  std::thread worker_;
};

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
