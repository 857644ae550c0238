#include "dormant_tree_modeling/modeling/sensor_calibration.h"

#include <yaml-cpp/yaml.h>

#include <algorithm>
#include <charconv>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <set>
#include <sstream>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace modeling {

namespace {

constexpr const char* ROOT_KEY = "sensor_calibration";
constexpr double MAX_ABS_BIAS_M = 0.05;
constexpr double MAX_RADIUS_M = 1.0;
constexpr double MAX_NOISE_M = 0.1;

[[noreturn]] void fail(ErrorCode code, const std::string& path, const std::string& what) {
  throw Error(code, "calibration file " + path + ": " + what);
}

/// `n` (named `where`) as a map with only the `allowed` keys.
void requireMap(const YAML::Node& n, const std::string& where, const std::set<std::string>& allowed,
                const std::string& path) {
  if (!n || !n.IsMap())
    fail(ErrorCode::PARSE_ERROR, path, "'" + where + "' is missing or not a map");
  for (const auto& kv : n) {
    const std::string k = kv.first.as<std::string>();
    if (!allowed.count(k))
      fail(ErrorCode::PARSE_ERROR, path, "unknown key '" + where + "." + k + "'");
  }
}

/// The map under `key`, with only the `allowed` keys.
YAML::Node section(const YAML::Node& parent, const std::string& key,
                   const std::set<std::string>& allowed, const std::string& path) {
  const YAML::Node n = parent[key];
  requireMap(n, key, allowed, path);
  return n;
}

std::vector<double> numbers(const YAML::Node& parent, const std::string& key,
                            const std::string& where, const std::string& path) {
  try {
    return parent[key].as<std::vector<double>>();
  } catch (const YAML::Exception&) {
    fail(ErrorCode::PARSE_ERROR, path,
         "'" + where + "." + key + "' is missing or not a list of numbers");
  }
}

RadiusCalibration readTable(const YAML::Node& root, const std::string& key,
                            const std::string& path) {
  const YAML::Node n = section(root, key, {"radii_m", "noise_m", "bias_m"}, path);
  RadiusCalibration t;
  t.radii = numbers(n, "radii_m", key, path);
  t.noise = numbers(n, "noise_m", key, path);
  t.bias = numbers(n, "bias_m", key, path);
  if (!t.valid()) {
    fail(ErrorCode::INVALID_ARGUMENT, path,
         key + ": radii_m and noise_m must be non-empty and ascending, bias_m must hold " +
             std::to_string(t.radii.size() * t.noise.size()) +
             " values (noise_m rows of radii_m; has " + std::to_string(t.bias.size()) + ")");
  }
  if (!(t.radii.front() > 0.0 && t.radii.back() <= MAX_RADIUS_M && t.noise.front() >= 0.0 &&
        t.noise.back() <= MAX_NOISE_M))
    fail(ErrorCode::INVALID_ARGUMENT, path,
         key + ": radii_m outside (0, 1] m or noise_m outside [0, 0.1] m");
  for (const double b : t.bias) {
    if (!(std::abs(b) <= MAX_ABS_BIAS_M))
      fail(ErrorCode::INVALID_ARGUMENT, path,
           key + ": a bias of " + std::to_string(b) + " m is beyond +/-0.05 m");
  }
  return t;
}

/// The rig scans' noise readings: a list of {radii_m, noise_m}, none when absent.
std::vector<NoiseReading> readNoiseReadings(const YAML::Node& root, const std::string& path) {
  std::vector<NoiseReading> out;
  const YAML::Node list = root["noise_readings"];
  if (!list)
    return out;
  if (!list.IsSequence())
    fail(ErrorCode::PARSE_ERROR, path, "'noise_readings' is not a list");
  for (std::size_t i = 0; i < list.size(); ++i) {
    const std::string where = "noise_readings[" + std::to_string(i) + "]";
    requireMap(list[i], where, {"radii_m", "noise_m"}, path);
    NoiseReading r{numbers(list[i], "radii_m", where, path),
                   numbers(list[i], "noise_m", where, path)};
    const bool noise_ok = std::all_of(r.noise_m.begin(), r.noise_m.end(),
                                      [](double v) { return v > 0.0 && v <= MAX_NOISE_M; });
    if (r.radii_m.empty() || r.radii_m.size() != r.noise_m.size() ||
        !strictlyAscending(r.radii_m) || !(r.radii_m.front() > 0.0) ||
        !(r.radii_m.back() <= MAX_RADIUS_M) || !noise_ok)
      fail(ErrorCode::INVALID_ARGUMENT, path,
           where + ": radii_m ascending in (0, 1] m and as many noise_m in (0, 0.1] m");
    out.push_back(std::move(r));
  }
  return out;
}

std::pair<double, double> range(const YAML::Node& n, const std::string& key,
                                const std::string& path) {
  const auto v = numbers(n, key, "covers", path);
  if (v.size() != 2 || !(v[0] >= 0.0 && v[1] >= v[0]))
    fail(ErrorCode::INVALID_ARGUMENT, path,
         "covers." + key + " must be [min, max] with 0 <= min <= max");
  return {v[0], v[1]};
}

/// The values as a YAML list, each the shortest decimal that reads back as the same double, so
/// that a file written and loaded again models trees as the calibration that was measured: a
/// model can turn micrometres of difference in its tables into millimetres (calibration.md).
std::string list(const std::vector<double>& v) {
  std::string s = "[";
  char buf[32];
  for (std::size_t i = 0; i < v.size(); ++i) {
    if (i)
      s += ", ";
    const auto end = std::to_chars(buf, buf + sizeof(buf), v[i]).ptr;
    s.append(buf, end);
  }
  return s + "]";
}

std::string tableYaml(const char* key, const RadiusCalibration& t) {
  std::string s = std::string("  ") + key + ":\n    radii_m: " + list(t.radii) +
                  "\n    noise_m: " + list(t.noise) + "\n    bias_m: [";
  const std::size_t n = t.radii.size();
  for (std::size_t k = 0; k < t.noise.size(); ++k) {
    const std::vector<double> row(t.bias.begin() + k * n, t.bias.begin() + (k + 1) * n);
    const std::string r = list(row);
    s += (k ? ",\n             " : "") + r.substr(1, r.size() - 2);
  }
  return s + "]\n";
}

}  // namespace

std::string fnv1aHex(const std::string& bytes) {
  std::uint64_t h = 0xcbf29ce484222325ULL;
  for (const unsigned char c : bytes) {
    h ^= c;
    h *= 0x100000001b3ULL;
  }
  char buf[17];
  std::snprintf(buf, sizeof(buf), "%016llx", static_cast<unsigned long long>(h));
  return buf;
}

SensorCalibration loadSensorCalibration(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec))
    throw Error(ErrorCode::FILE_NOT_FOUND, "no such calibration file: " + path);
  std::ifstream in(path, std::ios::binary);
  std::stringstream text;
  text << in.rdbuf();
  if (!in && !in.eof())
    throw Error(ErrorCode::IO_FAILURE, "cannot read calibration file " + path);
  YAML::Node doc;
  try {
    doc = YAML::Load(text.str());
  } catch (const YAML::Exception& e) {
    fail(ErrorCode::PARSE_ERROR, path, e.what());
  }
  if (!doc.IsMap() || !doc[ROOT_KEY])
    fail(ErrorCode::PARSE_ERROR, path, std::string("no top-level '") + ROOT_KEY + "' map");
  const YAML::Node root = section(doc, ROOT_KEY,
                                  {"name", "sources", "covers", "noise_readings", "trunk_footprint",
                                   "branch_footprint", "silhouette"},
                                  path);
  SensorCalibration c;
  try {
    c.name = root["name"].as<std::string>();
    if (root["sources"])
      c.sources = root["sources"].as<std::vector<std::string>>();
  } catch (const YAML::Exception&) {
    fail(ErrorCode::PARSE_ERROR, path, "'name' must be a string and 'sources' a list of strings");
  }
  if (c.name.empty())
    fail(ErrorCode::INVALID_ARGUMENT, path, "'name' is empty");
  c.trunk_footprint = readTable(root, "trunk_footprint", path);
  c.branch_footprint = readTable(root, "branch_footprint", path);
  const YAML::Node covers =
      section(root, "covers", {"trunk_radius_m", "branch_radius_m", "noise_m"}, path);
  std::tie(c.coverage.trunk_radius_min_m, c.coverage.trunk_radius_max_m) =
      range(covers, "trunk_radius_m", path);
  std::tie(c.coverage.branch_radius_min_m, c.coverage.branch_radius_max_m) =
      range(covers, "branch_radius_m", path);
  std::tie(c.coverage.noise_min_m, c.coverage.noise_max_m) = range(covers, "noise_m", path);
  c.noise_readings = readNoiseReadings(root, path);
  if (root["silhouette"]) {
    const YAML::Node s =
        section(root, "silhouette",
                {"growth_m", "growth_per_m", "ranges_m", "depth_share", "diameter_gain"}, path);
    const auto growth = numbers(s, "growth_m", "silhouette", path);
    const auto per_m = numbers(s, "growth_per_m", "silhouette", path);
    const auto ranges = numbers(s, "ranges_m", "silhouette", path);
    if (growth.size() != 1 || per_m.size() != 1 || ranges.size() != 2 ||
        !(std::abs(growth[0]) <= MAX_ABS_BIAS_M && std::abs(per_m[0]) <= MAX_ABS_BIAS_M) ||
        !(ranges[0] >= 0.0 && ranges[1] >= ranges[0]))
      fail(ErrorCode::INVALID_ARGUMENT, path,
           "silhouette: growth_m and growth_per_m are [one number] within +/-0.05, ranges_m is "
           "[min, max]");
    const auto share =
        s["depth_share"] ? numbers(s, "depth_share", "silhouette", path) : std::vector<double>{1.0};
    if (share.size() != 1 || !(share[0] >= 0.0 && share[0] <= 2.0))
      fail(ErrorCode::INVALID_ARGUMENT, path, "silhouette: depth_share is [one number] in [0, 2]");
    // Files written before the gain was measured assumed 1: the footprint only adds a margin.
    const auto gain = s["diameter_gain"] ? numbers(s, "diameter_gain", "silhouette", path)
                                         : std::vector<double>{1.0};
    if (gain.size() != 1 || !validDiameterGain(gain[0]))
      fail(ErrorCode::INVALID_ARGUMENT, path,
           "silhouette: diameter_gain is [one number] in " + diameterGainRange());
    c.silhouette = {true, growth[0], per_m[0], ranges[0], ranges[1], share[0], gain[0]};
  }
  c.hash = fnv1aHex(text.str());
  return c;
}

double NoiseReading::at(double radius) const {
  if (radii_m.size() < 2)
    return radii_m.empty() ? 0.0 : noise_m.front();
  const auto [i, t] = gridPosition(radii_m, radius);
  return (1.0 - t) * noise_m[i] + t * noise_m[i + 1];
}

double SensorCalibration::standardReading(double sigma,
                                          const std::vector<double>& slice_radii) const {
  if (noise_readings.empty() || slice_radii.empty())
    return sigma;
  // Per rig scan: its reading on the tree's slices (their mean) and its standard reading.
  std::vector<std::pair<double, double>> pairs;
  for (const NoiseReading& r : noise_readings) {
    double sum = 0.0;
    for (const double x : slice_radii)
      sum += r.at(x);
    pairs.emplace_back(sum / slice_radii.size(), r.at(STANDARD_READING_RADIUS_M));
  }
  std::sort(pairs.begin(), pairs.end());
  std::vector<double> on_slices, standard;
  for (const auto& [a, b] : pairs) {
    on_slices.push_back(a);
    standard.push_back(b);
  }
  return mapAlong(on_slices, standard, sigma);
}

std::string diameterGainRange() {
  char text[48];
  std::snprintf(text, sizeof(text), "[%g, %g]", MIN_DIAMETER_GAIN, MAX_DIAMETER_GAIN);
  return text;
}

std::string sensorCalibrationToYaml(const SensorCalibration& c, const std::string& comment) {
  std::ostringstream s;
  std::istringstream lines(comment);
  for (std::string line; std::getline(lines, line);)
    s << "# " << line << "\n";
  s << ROOT_KEY << ":\n  name: " << YAML::Node(c.name) << "\n";
  if (!c.sources.empty()) {
    s << "  sources:\n";
    for (const auto& src : c.sources)
      s << "    - " << YAML::Node(src) << "\n";
  }
  const auto& v = c.coverage;
  s << "  covers:\n    trunk_radius_m: " << list({v.trunk_radius_min_m, v.trunk_radius_max_m})
    << "\n    branch_radius_m: " << list({v.branch_radius_min_m, v.branch_radius_max_m})
    << "\n    noise_m: " << list({v.noise_min_m, v.noise_max_m}) << "\n";
  if (!c.noise_readings.empty()) {
    s << "  noise_readings:\n";
    for (const NoiseReading& r : c.noise_readings)
      s << "    - radii_m: " << list(r.radii_m) << "\n      noise_m: " << list(r.noise_m) << "\n";
  }
  s << tableYaml("trunk_footprint", c.trunk_footprint)
    << tableYaml("branch_footprint", c.branch_footprint);
  if (c.silhouette.measured) {
    s << "  silhouette:\n    growth_m: " << list({c.silhouette.growth_m})
      << "\n    growth_per_m: " << list({c.silhouette.growth_per_m})
      << "\n    ranges_m: " << list({c.silhouette.range_min_m, c.silhouette.range_max_m})
      << "\n    depth_share: " << list({c.silhouette.depth_share})
      << "\n    diameter_gain: " << list({c.silhouette.diameter_gain}) << "\n";
  }
  return s.str();
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
