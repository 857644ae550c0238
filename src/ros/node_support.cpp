#include "dormant_tree_modeling/ros/node_support.h"

#include <algorithm>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace ros_layer {

void NodeDiagnostics::start(ros::NodeHandle& nh, const std::string& hardware_id) {
  updater_.setHardwareID(hardware_id);
  timer_ =
      nh.createTimer(ros::Duration(1.0), [this](const ros::TimerEvent&) { updater_.update(); });
}

YAML::Node toYaml(const XmlRpc::XmlRpcValue& value) {
  XmlRpc::XmlRpcValue v = value;  // the accessors are not const
  switch (v.getType()) {
    case XmlRpc::XmlRpcValue::TypeBoolean:
      return YAML::Node(static_cast<bool>(v));
    case XmlRpc::XmlRpcValue::TypeInt:
      return YAML::Node(static_cast<int>(v));
    case XmlRpc::XmlRpcValue::TypeDouble:
      return YAML::Node(static_cast<double>(v));
    case XmlRpc::XmlRpcValue::TypeString:
      return YAML::Node(static_cast<std::string>(v));
    case XmlRpc::XmlRpcValue::TypeArray: {
      YAML::Node list(YAML::NodeType::Sequence);
      for (int i = 0; i < v.size(); ++i)
        list.push_back(toYaml(v[i]));
      return list;
    }
    default:
      throw Error(ErrorCode::PARSE_ERROR,
                  "a parameter holds a map, a date or binary data where "
                  "a number, a switch, a name or a list belongs");
  }
}

std::vector<std::pair<std::string, std::string>> privateParameters(const ros::NodeHandle& pnh) {
  std::vector<std::string> names;
  std::vector<std::pair<std::string, std::string>> out;
  if (!ros::param::getParamNames(names))
    return out;  // no master: nothing set, the defaults stand
  const std::string ns = pnh.getNamespace() + "/";
  for (const auto& full : names) {
    if (full.rfind(ns, 0) != 0)
      continue;
    std::string key = full.substr(ns.size());
    std::replace(key.begin(), key.end(), '/', '.');
    out.emplace_back(full, key);
  }
  return out;
}

}  // namespace ros_layer
}  // namespace dormant_tree_modeling
