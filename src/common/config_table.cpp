#include "dormant_tree_modeling/common/config_table.h"

#include <cmath>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <sstream>

namespace dormant_tree_modeling {
namespace config_detail {

namespace {

/// Numbers as a person writes them: integral values without a fraction, others with the fewest
/// digits that read back exactly.
std::string formatNumber(double v) {
  if (std::isfinite(v) && v == std::floor(v) && std::fabs(v) < 1e15) {
    char buf[32];
    std::snprintf(buf, sizeof buf, "%.0f", v);
    return buf;
  }
  char buf[40];
  for (int precision = 1; precision <= 17; ++precision) {
    std::snprintf(buf, sizeof buf, "%.*g", precision, v);
    if (std::strtod(buf, nullptr) == v)
      break;
  }
  return buf;
}

std::string groupOf(const std::string& key) {
  const auto dot = key.rfind('.');
  return dot == std::string::npos ? std::string() : key.substr(0, dot);
}

std::string leafOf(const std::string& key) {
  const auto dot = key.rfind('.');
  return dot == std::string::npos ? key : key.substr(dot + 1);
}

/// Wrap text into comment lines of at most `width` characters after the indent.
void writeComment(std::ostringstream& out, const std::string& indent, const std::string& text) {
  constexpr std::size_t WIDTH = 96;
  std::istringstream words(text);
  std::string word, line;
  while (words >> word) {
    if (!line.empty() && indent.size() + 2 + line.size() + 1 + word.size() > WIDTH) {
      out << indent << "# " << line << "\n";
      line.clear();
    }
    line += (line.empty() ? "" : " ") + word;
  }
  if (!line.empty())
    out << indent << "# " << line << "\n";
}

void collectLeaves(const YAML::Node& map, const std::string& prefix,
                   std::vector<std::pair<std::string, YAML::Node>>& out) {
  for (const auto& kv : map) {
    const std::string key = prefix + kv.first.as<std::string>();
    if (kv.second.IsMap())
      collectLeaves(kv.second, key + ".", out);
    else
      out.emplace_back(key, kv.second);
  }
}

}  // namespace

std::string formatValue(double v) {
  const std::string s = formatNumber(v);
  // A float stays a float when read back by a YAML reader that types scalars.
  return s.find_first_of(".en") == std::string::npos ? s + ".0" : s;
}

std::string formatValue(bool v) {
  return v ? "true" : "false";
}

std::string formatValue(const std::string& v) {
  YAML::Emitter e;
  e << v;
  return v.empty() ? "\"\"" : std::string(e.c_str());
}

std::string formatValue(const std::vector<double>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i)
    s += (i ? ", " : "") + formatValue(v[i]);
  return s + "]";
}

std::string formatValue(const std::vector<std::string>& v) {
  std::string s = "[";
  for (std::size_t i = 0; i < v.size(); ++i)
    s += (i ? ", " : "") + formatValue(v[i]);
  return s + "]";
}

std::string formatValue(const Eigen::Vector3d& v) {
  return formatValue(std::vector<double>{v.x(), v.y(), v.z()});
}

std::string rangeText(double lo, double hi) {
  return "[" + formatNumber(lo) + ", " + formatNumber(hi) + "]";
}

std::string outsideMessage(const std::string& what, const std::string& key, double value, double lo,
                           double hi) {
  if (value >= lo && value <= hi)
    return {};
  return what + " " + key + " = " + formatNumber(value) + " is outside " + rangeText(lo, hi);
}

std::vector<std::pair<std::string, YAML::Node>> yamlLeaves(const std::string& path,
                                                           const std::string& section,
                                                           const std::string& what) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw Error(ErrorCode::FILE_NOT_FOUND, "no such file: " + path);
  YAML::Node root;
  try {
    root = YAML::LoadFile(path);
  } catch (const YAML::Exception& e) {
    throw Error(ErrorCode::PARSE_ERROR, path + ": " + e.what());
  }
  if (!section.empty() && root.IsMap() && root[section])
    root = root[section];
  if (root.IsNull())
    return {};
  if (!root.IsMap())
    throw Error(ErrorCode::PARSE_ERROR, path + ": expected a map of " + what + "s");
  std::vector<std::pair<std::string, YAML::Node>> out;
  collectLeaves(root, "", out);
  return out;
}

std::string writeYaml(const std::vector<std::pair<FieldInfo, std::string>>& fields,
                      const std::string& section, const std::string& header) {
  std::ostringstream out;
  writeComment(out, "", header);
  const std::string base = section.empty() ? "" : "  ";
  if (!section.empty())
    out << section << ":\n";
  std::string group;
  std::vector<std::string> closed;
  bool first = true;
  for (const auto& [info, value] : fields) {
    const std::string g = groupOf(info.key);
    if (first || g != group) {
      for (const auto& c : closed) {
        if (c == g)
          throw Error(ErrorCode::INVALID_ARGUMENT, "config table: group '" + g + "' is split");
      }
      if (!first)
        closed.push_back(group);
      first = false;
      group = g;
      out << "\n";
      if (!g.empty())
        out << base << g << ":\n";
    }
    const std::string indent = base + (g.empty() ? "" : "  ");
    std::string doc = info.doc;
    if (!info.range.empty())
      doc += " Valid: " + info.range + ".";
    writeComment(out, indent, doc);
    out << indent << leafOf(info.key) << ": " << value << "\n";
  }
  return out.str();
}

std::string writeMarkdown(const std::vector<std::pair<FieldInfo, std::string>>& fields,
                          const std::string& section) {
  const auto cell = [](std::string s) {
    for (std::size_t p = 0; (p = s.find('|', p)) != std::string::npos; p += 2)
      s.replace(p, 1, "\\|");
    return s;
  };
  std::ostringstream out;
  out << "| " << (section.empty() ? "key" : "key (under `" + section + ":`)")
      << " | default | valid | meaning |\n|---|---|---|---|\n";
  for (const auto& [info, value] : fields) {
    out << "| `" << info.key << "` | `" << cell(value) << "` | " << cell(info.range) << " | "
        << cell(info.doc) << " |\n";
  }
  return out.str();
}

}  // namespace config_detail
}  // namespace dormant_tree_modeling
