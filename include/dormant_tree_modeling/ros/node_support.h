#pragma once

#include <diagnostic_updater/diagnostic_updater.h>
#include <ros/ros.h>

#include <yaml-cpp/yaml.h>

#include <functional>
#include <string>
#include <vector>

#include "dormant_tree_modeling/common/config_table.h"

namespace dormant_tree_modeling {
namespace ros_layer {

/// @brief A node's `/diagnostics`: its tasks, published once a second from start().
class NodeDiagnostics {
 public:
  /// @brief Names what the diagnostics are about and starts publishing them once a second.
  /// @param hardware_id the device ("LMS111 192.168.0.1:2111"), "none" for a software node
  void start(ros::NodeHandle& nh, const std::string& hardware_id);

  /// @brief Adds a task whose status the owner's member `fill` writes.
  template <class T>
  void add(const std::string& task, T* owner,
           void (T::*fill)(diagnostic_updater::DiagnosticStatusWrapper&)) {
    updater_.add(task, owner, fill);
  }
  /// @brief Adds a task kept by the caller (a frequency status, for one), for the node's life.
  void add(diagnostic_updater::DiagnosticTask& task) { updater_.add(task); }

 private:
  diagnostic_updater::Updater updater_;
  ros::Timer timer_;
};

/// @brief A parameter server value as YAML, for ConfigTable::set.
/// @throws Error PARSE_ERROR for a struct, a date or binary data
YAML::Node toYaml(const XmlRpc::XmlRpcValue& value);

/// @brief The node's private parameters on the server: each leaf's full name and its key in a
/// field table (groups, the namespaces below the node's, joined by '.'). Empty without a master.
std::vector<std::pair<std::string, std::string>> privateParameters(const ros::NodeHandle& pnh);

/// @brief A node's parameters through the same table as its YAML file: each private parameter
/// that is a key of the table is read (groups as `group/key`), the rest of `config` keeps its
/// defaults. A parameter still set under a renamed or retired name stops the node with where
/// it went; one the table does not know is warned of (a misspelt name would otherwise be
/// ignored without a word).
/// @throws Error PARSE_ERROR for a value of the wrong type or a stale name; does not validate
template <typename Config>
Config readParameters(const ros::NodeHandle& pnh, const ConfigTable<Config>& table,
                      Config config = Config{}) {
  for (const auto& [name, key] : privateParameters(pnh)) {
    const std::string origin = "parameter " + name;
    XmlRpc::XmlRpcValue value;
    if (!table.has(key)) {
      table.refuseStaleKey(key, origin);
      ROS_WARN("unknown parameter %s: not used (see docs/configuration.md)", name.c_str());
    } else if (ros::param::get(name, value)) {
      table.set(key, toYaml(value), config, origin);
    }
  }
  return config;
}

/// @brief The main of a node class: ros::init, the node built from the public and the private
/// node handle, its callbacks on `threads` threads until shutdown, then `on_shutdown(node)`
/// (while the spinner still runs: a call waiting in a callback can be ended), whose result is
/// the exit status. A node that cannot start (a bad parameter, an unreadable file) is logged
/// as FATAL and the process exits with 1.
template <class Node>
int runNode(int argc, char** argv, const char* name, int threads,
            const std::function<int(Node&)>& on_shutdown = {}) {
  ros::init(argc, argv, name);
  ros::NodeHandle nh;
  ros::NodeHandle pnh("~");
  try {
    Node node(nh, pnh);
    if (threads <= 1) {
      ros::spin();
      return on_shutdown ? on_shutdown(node) : 0;
    }
    ros::AsyncSpinner spinner(threads);
    spinner.start();
    ros::waitForShutdown();
    return on_shutdown ? on_shutdown(node) : 0;
  } catch (const std::exception& e) {
    ROS_FATAL("%s: %s", name, e.what());
    return 1;
  }
}

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
