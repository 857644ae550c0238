#pragma once

#include <yaml-cpp/yaml.h>

#include <Eigen/Core>
#include <functional>
#include <string>
#include <type_traits>
#include <typeinfo>
#include <utility>
#include <vector>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {

/// @brief What a field table knows about one parameter, apart from where it lives.
struct FieldInfo {
  std::string key;         ///< dotted path with the unit last, e.g. "trunk.slice_height_m"
  std::string doc;         ///< one sentence: what it does and why its default
  std::string range;       ///< valid values as text ("[0.01, 0.5]", "cola_a | cola_b"), or empty
  std::string former_key;  ///< the name before a rename (a clear error when a file still uses it)
};

namespace config_detail {

/// @brief Shortest text that reads back to the same value ("0.004", not "0.0040000000000000001").
std::string formatValue(double v);
std::string formatValue(bool v);
std::string formatValue(const std::string& v);
std::string formatValue(const std::vector<double>& v);
std::string formatValue(const std::vector<std::string>& v);
std::string formatValue(const Eigen::Vector3d& v);
template <typename T>
std::enable_if_t<std::is_integral_v<T> && !std::is_same_v<T, bool>, std::string> formatValue(T v) {
  return std::to_string(v);
}

/// @brief "what key = value is outside [lo, hi]", or empty when inside.
std::string outsideMessage(const std::string& what, const std::string& key, double value, double lo,
                           double hi);
std::string rangeText(double lo, double hi);

/// @brief The leaves of a YAML file's map (nested maps are groups: "group.key"), read from the
/// `section` map when the root holds one.
/// @throws Error FILE_NOT_FOUND; PARSE_ERROR for malformed YAML or a root that is no map
std::vector<std::pair<std::string, YAML::Node>> yamlLeaves(const std::string& path,
                                                           const std::string& section,
                                                           const std::string& what);

/// @brief The fields written as nested YAML (groups as maps), each with its doc as a comment.
std::string writeYaml(const std::vector<std::pair<FieldInfo, std::string>>& fields,
                      const std::string& section, const std::string& header);
/// @brief The fields as a Markdown table: key, default, range, meaning.
std::string writeMarkdown(const std::vector<std::pair<FieldInfo, std::string>>& fields,
                          const std::string& section);

}  // namespace config_detail

/// @brief The one description of a config struct's parameters: each field's key (with its unit),
/// its valid range and its meaning, and how to reach it in the struct. Loading a YAML file or
/// ROS parameters, validation, the shipped YAML and docs/configuration.md all come from it, so a
/// parameter is written down once.
template <typename Config>
class ConfigTable {
 public:
  /// @param what what one entry is, for messages ("tree modeler parameter")
  /// @param section the top-level key of the YAML file ("tree_modeler"), or empty
  ConfigTable(std::string what, std::string section)
      : what_(std::move(what)), section_(std::move(section)) {}

  /// @brief A number (or a list of numbers, each) that must lie in [lo, hi].
  template <typename Owner, typename T, typename Bound>
  ConfigTable& add(const std::string& key, T Owner::*member, Bound lo, Bound hi,
                   const std::string& doc) {
    static_assert(std::is_arithmetic_v<Bound>, "bounds are numbers");
    Field f = plain(key, member, doc);
    f.info.range = config_detail::rangeText(lo, hi);
    const auto get = getter<Owner, T>(member);
    const std::string what = what_;
    f.problem = [get, lo, hi, key, what](const Config& c) {
      if constexpr (std::is_arithmetic_v<T>) {
        return config_detail::outsideMessage(what, key, static_cast<double>(get(c)), lo, hi);
      } else {
        if constexpr (!std::is_same_v<T, Eigen::Vector3d>) {
          if (get(c).empty())
            return what + " " + key + " must not be empty";
        }
        for (const double v : get(c)) {
          const std::string m = config_detail::outsideMessage(what, key, v, lo, hi);
          if (!m.empty())
            return m;
        }
        return std::string();
      }
    };
    fields_.push_back(std::move(f));
    return *this;
  }

  /// @brief A switch, a name or a value any of its type may take.
  template <typename Owner, typename T>
  ConfigTable& add(const std::string& key, T Owner::*member, const std::string& doc) {
    fields_.push_back(plain(key, member, doc));
    return *this;
  }

  /// @brief The fields added next live in this nested struct (`group(&Config::trunk)`); their
  /// keys name the group themselves ("trunk.slice_height_m").
  template <typename Group>
  ConfigTable& group(Group Config::*member) {
    group_ = [member](Config& c) -> void* { return &(c.*member); };
    group_type_ = &typeid(Group);
    return *this;
  }
  /// @brief An enumeration, written by name.
  template <typename Owner, typename E>
  ConfigTable& names(const std::string& key, E Owner::*member,
                     const std::vector<std::pair<std::string, E>>& values, const std::string& doc) {
    static_assert(std::is_enum_v<E> || std::is_same_v<E, bool>,
                  "names() is for enumerations and two-way choices");
    Field f;
    f.info.key = key;
    f.info.doc = doc;
    for (const auto& v : values)
      f.info.range += (f.info.range.empty() ? "" : " | ") + v.first;
    const auto get = getter<Owner, E>(member);
    const auto set = mutableGetter<Owner, E>(member);
    const std::string what = what_, range = f.info.range;
    f.read = [set, values, what, key, range](Config& c, const YAML::Node& n) {
      const std::string name = n.as<std::string>();
      for (const auto& v : values) {
        if (v.first == name) {
          set(c) = v.second;
          return;
        }
      }
      throw Error(ErrorCode::INVALID_ARGUMENT,
                  what + " " + key + " = '" + name + "' is not one of " + range);
    };
    f.show = [get, values](const Config& c) {
      for (const auto& v : values) {
        if (v.second == get(c))
          return v.first;
      }
      return std::string("?");
    };
    f.type = "a name";
    fields_.push_back(std::move(f));
    return *this;
  }

  /// @brief Every field of a nested struct that has a table of its own, under `prefix.` (or
  /// under its own keys when `prefix` is empty).
  template <typename Sub>
  ConfigTable& include(const std::string& prefix, Sub Config::*member,
                       const ConfigTable<Sub>& sub) {
    for (const auto& f : sub.fields_) {
      Field g;
      g.info = f.info;
      g.info.key = prefix.empty() ? f.info.key : prefix + "." + f.info.key;
      g.type = f.type;
      g.read = [member, r = f.read](Config& c, const YAML::Node& n) { r(c.*member, n); };
      g.show = [member, s = f.show](const Config& c) { return s(c.*member); };
      if (f.problem) {
        g.problem = [member, p = f.problem, prefix, what = what_,
                     sub_what = sub.what_](const Config& c) {
          std::string m = p(c.*member);
          if (!m.empty() && m.rfind(sub_what, 0) == 0)
            m = what + " " + (prefix.empty() ? "" : prefix + ".") + m.substr(sub_what.size() + 1);
          return m;
        };
      }
      fields_.push_back(std::move(g));
    }
    return *this;
  }

  /// @brief Back to fields of Config itself.
  ConfigTable& topLevel() {
    group_ = nullptr;
    group_type_ = nullptr;
    return *this;
  }

  /// @brief The last field's name before a rename: a file still using it gets an error that
  /// names the new key, instead of "unknown".
  ConfigTable& formerly(const std::string& old_key) {
    fields_.back().info.former_key = old_key;
    return *this;
  }

  /// @brief Keys that are no longer parameters at all (a trailing '*' matches a prefix): a file
  /// still using one gets `why` (where the setting lives now) instead of "unknown".
  ConfigTable& retired(const std::vector<std::string>& keys, const std::string& why) {
    for (const auto& k : keys)
      retired_.emplace_back(k, why);
    return *this;
  }

  /// @brief Set one field from a YAML value.
  /// @param origin where the value came from, for messages (a file, "ROS parameter")
  /// @throws Error PARSE_ERROR for an unknown key or a value of the wrong type
  void set(const std::string& key, const YAML::Node& value, Config& c,
           const std::string& origin) const {
    for (const auto& f : fields_) {
      if (f.info.key != key)
        continue;
      try {
        f.read(c, value);
      } catch (const Error& e) {
        throw Error(e.code(), origin + ": " + e.what());
      } catch (const YAML::Exception&) {
        throw Error(ErrorCode::PARSE_ERROR, origin + ": " + what_ + " '" + key +
                                                "' has the wrong type (expected " + f.type + ")");
      }
      return;
    }
    refuseStaleKey(key, origin);
    throw Error(ErrorCode::PARSE_ERROR, origin + ": unknown " + what_ + " '" + key + "'");
  }

  /// @brief For a key that is no field: an error naming the new key of a renamed one, or where
  /// a retired one's setting lives now; nothing for a key never known.
  /// @throws Error PARSE_ERROR
  void refuseStaleKey(const std::string& key, const std::string& origin) const {
    for (const auto& f : fields_) {
      if (!f.info.former_key.empty() && f.info.former_key == key) {
        throw Error(ErrorCode::PARSE_ERROR,
                    origin + ": " + what_ + " '" + key + "' is now '" + f.info.key + "'");
      }
    }
    for (const auto& [pattern, why] : retired_) {
      const bool prefix = !pattern.empty() && pattern.back() == '*';
      if (prefix ? key.rfind(pattern.substr(0, pattern.size() - 1), 0) == 0 : key == pattern)
        throw Error(ErrorCode::PARSE_ERROR,
                    origin + ": '" + key + "' is no longer a " + what_ + ": " + why);
    }
  }

  /// @brief Set the fields a YAML file names (nested maps are groups); the rest keep their value.
  /// @throws Error FILE_NOT_FOUND, PARSE_ERROR (does not validate)
  void load(const std::string& path, Config& c) const {
    for (const auto& [key, value] : config_detail::yamlLeaves(path, section_, what_))
      set(key, value, c, path);
  }

  /// @brief Each field within its range.
  /// @throws Error INVALID_ARGUMENT naming the first field outside, its value and the range
  void check(const Config& c) const {
    for (const auto& f : fields_) {
      const std::string m = f.problem ? f.problem(c) : std::string();
      if (!m.empty())
        throw Error(ErrorCode::INVALID_ARGUMENT, m);
    }
  }

  /// @brief A check between fields that no range expresses.
  /// @throws Error INVALID_ARGUMENT "<what> <message>" unless ok
  void require(bool ok, const std::string& message) const {
    if (!ok)
      throw Error(ErrorCode::INVALID_ARGUMENT, what_ + " " + message);
  }

  /// @brief Whether `key` is one of the table's fields.
  bool has(const std::string& key) const {
    for (const auto& f : fields_) {
      if (f.info.key == key)
        return true;
    }
    return false;
  }
  const std::string& what() const { return what_; }

  /// @brief The config as a YAML file this table loads, each key with its doc as a comment.
  std::string yaml(const Config& c, const std::string& header) const {
    return config_detail::writeYaml(shown(c), section_, header);
  }
  /// @brief The fields as a Markdown table with c's values as the defaults.
  std::string markdown(const Config& c) const {
    return config_detail::writeMarkdown(shown(c), section_);
  }

 private:
  template <typename Other>
  friend class ConfigTable;

  struct Field {
    FieldInfo info;
    std::function<void(Config&, const YAML::Node&)> read;
    std::function<std::string(const Config&)> show;
    std::function<std::string(const Config&)> problem;
    const char* type = "";
  };

  template <typename Owner, typename T>
  std::function<const T&(const Config&)> getter(T Owner::*member) const {
    if constexpr (std::is_same_v<Owner, Config>) {
      return [member](const Config& c) -> const T& { return c.*member; };
    } else {
      const auto g = group_;
      return [g, member](const Config& c) -> const T& {
        return static_cast<const Owner*>(g(const_cast<Config&>(c)))->*member;
      };
    }
  }
  template <typename Owner, typename T>
  std::function<T&(Config&)> mutableGetter(T Owner::*member) const {
    if constexpr (std::is_same_v<Owner, Config>) {
      return [member](Config& c) -> T& { return c.*member; };
    } else {
      const auto g = group_;
      return [g, member](Config& c) -> T& { return static_cast<Owner*>(g(c))->*member; };
    }
  }

  template <typename Owner, typename T>
  Field plain(const std::string& key, T Owner::*member, const std::string& doc) const {
    if constexpr (!std::is_same_v<Owner, Config>) {
      if (!group_ || *group_type_ != typeid(Owner))
        throw Error(ErrorCode::INVALID_ARGUMENT, key + ": its struct needs group() first");
    }
    Field f;
    f.info.key = key;
    f.info.doc = doc;
    const auto get = getter<Owner, T>(member);
    const auto set = mutableGetter<Owner, T>(member);
    f.read = [set](Config& c, const YAML::Node& n) { set(c) = n.as<T>(); };
    f.show = [get](const Config& c) { return config_detail::formatValue(get(c)); };
    f.type = typeName<T>();
    return f;
  }

  template <typename T>
  static const char* typeName() {
    if constexpr (std::is_same_v<T, bool>)
      return "true or false";
    else if constexpr (std::is_integral_v<T>)
      return "an integer";
    else if constexpr (std::is_floating_point_v<T>)
      return "a number";
    else if constexpr (std::is_same_v<T, std::string>)
      return "a string";
    else if constexpr (std::is_same_v<T, Eigen::Vector3d>)
      return "a list [x, y, z]";
    else
      return "a list";
  }

  std::vector<std::pair<FieldInfo, std::string>> shown(const Config& c) const {
    std::vector<std::pair<FieldInfo, std::string>> out;
    for (const auto& f : fields_)
      out.emplace_back(f.info, f.show(c));
    return out;
  }

  std::string what_;
  std::string section_;
  std::function<void*(Config&)> group_;
  const std::type_info* group_type_ = nullptr;
  std::vector<Field> fields_;
  std::vector<std::pair<std::string, std::string>> retired_;
};

}  // namespace dormant_tree_modeling

namespace YAML {
/// A 3-vector as a YAML list [x, y, z] (mounting offsets).
template <>
struct convert<Eigen::Vector3d> {
  static bool decode(const Node& node, Eigen::Vector3d& v) {
    if (!node.IsSequence() || node.size() != 3)
      return false;
    for (std::size_t i = 0; i < 3; ++i)
      v[static_cast<Eigen::Index>(i)] = node[i].as<double>();
    return true;
  }
};
}  // namespace YAML
