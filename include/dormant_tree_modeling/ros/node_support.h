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

/// @brief Stops with the new name when a renamed parameter is still set; warns once per
/// private parameter that neither the table nor `others` knows (a misspelt parameter would
/// otherwise be ignored without a word).
void checkParameterNames(const ros::NodeHandle& pnh, const std::vector<FieldInfo>& fields,
                         const std::vector<std::string>& others);

/// @brief A node's parameters through the same table as its YAML file: each key (groups as
/// `group/key`) read from the private namespace when set, else the default in `config`.
/// @param others private parameters the node reads outside the table
/// @throws Error PARSE_ERROR for a value of the wrong type or a renamed key; does not validate
template <typename Config>
Config readParameters(const ros::NodeHandle& pnh, const ConfigTable<Config>& table,
                      Config config = Config{}, const std::vector<std::string>& others = {}) {
  checkParameterNames(pnh, table.fields(), others);
  for (const auto& field : table.fields()) {
    std::string name = field.key;
    for (auto& ch : name)
      ch = ch == '.' ? '/' : ch;
    XmlRpc::XmlRpcValue value;
    if (pnh.getParam(name, value))
      table.set(field.key, toYaml(value), config, "parameter " + pnh.resolveName(name));
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
