#pragma once

#include <yaml-cpp/yaml.h>

#include <functional>
#include <string>

namespace dormant_tree_modeling {

/// @brief Read a YAML file of `key: value` settings and hand every entry to `apply`.
/// @param path the file
/// @param section when the root holds this key, its map is read instead (e.g. "tree_modeler:")
/// @param what what the settings are, for messages ("view plan", "tree modeler parameter")
/// @param apply sets one entry; returns false for a key it does not know
/// @throws Error FILE_NOT_FOUND; PARSE_ERROR for malformed YAML, a root that is no map, an
///         unknown key or a value of the wrong type, naming the file and the key
void forEachYamlEntry(const std::string& path, const std::string& section, const std::string& what,
                      const std::function<bool(const std::string&, const YAML::Node&)>& apply);

}  // namespace dormant_tree_modeling
