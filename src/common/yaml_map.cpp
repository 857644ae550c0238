#include "dormant_tree_modeling/common/yaml_map.h"

#include <filesystem>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {

void forEachYamlEntry(const std::string& path, const std::string& section, const std::string& what,
                      const std::function<bool(const std::string&, const YAML::Node&)>& apply) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw Error(ErrorCode::FILE_NOT_FOUND, "no such file: " + path);
  }
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw Error(ErrorCode::PARSE_ERROR, path + ": " + e.what());
  }
  if (!section.empty() && root.IsMap() && root[section])
    root = root[section];
  if (!root.IsMap())
    throw Error(ErrorCode::PARSE_ERROR, path + ": expected a map of " + what + "s");
  for (const auto& kv : root) {
    const std::string key = kv.first.as<std::string>();
    bool known = false;
    try {
      known = apply(key, kv.second);
    } catch (const YAML::Exception&) {
      throw Error(ErrorCode::PARSE_ERROR, path + ": " + what + " '" + key + "' has the wrong type");
    }
    if (!known)
      throw Error(ErrorCode::PARSE_ERROR, path + ": unknown " + what + " '" + key + "'");
  }
}

}  // namespace dormant_tree_modeling
