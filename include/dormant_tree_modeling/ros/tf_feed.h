#pragma once

#include <geometry_msgs/TransformStamped.h>
#include <ros/callback_queue.h>
#include <ros/ros.h>
#include <tf2_msgs/TFMessage.h>
#include <tf2_ros/buffer.h>

#include <memory>
#include <string>

namespace dormant_tree_modeling {
namespace ros_layer {

/// @brief How much tf history the nodes keep (s). tf's default, 10 s, is too short for a
/// replay: a player that fell behind delivers many seconds at once, and the views being
/// assembled then ask for times that a 10 s cache has already dropped.
constexpr double TF_CACHE_S = 120.0;

/// @brief Feeds /tf and /tf_static into a buffer on a thread of its own, like
/// tf2_ros::TransformListener, but with a deep subscriber queue: the listener's 100 messages
/// lose transforms when a replay delivers seconds at once, and interpolating across the gap
/// gives a view another pose than the live run gave it.
class TfFeed {
 public:
  /// @param buffer the buffer to fill (outlives the feed)
  /// @param queue_size messages held per topic while the feed's thread catches up
  explicit TfFeed(tf2_ros::Buffer& buffer, int queue_size = 5000);
  ~TfFeed();
  TfFeed(const TfFeed&) = delete;
  TfFeed& operator=(const TfFeed&) = delete;

 private:
  void add(const tf2_msgs::TFMessage& msg, const std::string& authority, bool is_static);

  tf2_ros::Buffer& buffer_;
  ros::NodeHandle nh_;
  ros::CallbackQueue queue_;
  ros::Subscriber tf_sub_, static_sub_;
  std::unique_ptr<ros::AsyncSpinner> spinner_;
};

/// @brief Whether the buffer has heard of `frame` at all, so that a lookup that can never
/// succeed is not waited for. tf2's only existence query is the underscored `_frameExists`,
/// and `canTransform(f, f)` answers true for any name, so this reads the public frame list
/// (`allFramesAsYAML`: each frame with a parent as a key, a root frame as a parent).
bool frameKnown(const tf2_ros::Buffer& buffer, const std::string& frame);

/// @brief tf lookup that waits for the transform in wall time.
///
/// tf2's own timeout runs on ros::Time: in a replay, sim time stands still whenever the bag
/// player falls behind or has ended, and a lookup waiting for it would never return.
/// @param buffer the tf buffer
/// @param target target frame
/// @param source source frame
/// @param stamp time of the transform (0: the latest)
/// @param wall_timeout_s how long to wait for it, in wall-clock seconds
/// @throws tf2::TransformException with tf's reason when it is still unavailable
geometry_msgs::TransformStamped lookupWithin(const tf2_ros::Buffer& buffer,
                                             const std::string& target, const std::string& source,
                                             const ros::Time& stamp, double wall_timeout_s);

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
