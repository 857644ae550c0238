#include "dormant_tree_modeling/io/tree_json.h"

#include <cmath>
#include <filesystem>
#include <fstream>
#include <nlohmann/json.hpp>
#include <sstream>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace io {

using nlohmann::json;

namespace {

constexpr double RAD_TO_DEG = 180.0 / M_PI;

json vec(const Eigen::Vector3d& v) {
  return json::array({v.x(), v.y(), v.z()});
}

[[noreturn]] void fail(const std::string& what) {
  throw Error(ErrorCode::PARSE_ERROR, what);
}

const json& member(const json& obj, const char* key, const std::string& where) {
  if (!obj.is_object())
    fail(where + " is not an object");
  const auto it = obj.find(key);
  if (it == obj.end())
    fail(where + " has no '" + key + "'");
  return *it;
}

double number(const json& obj, const char* key, const std::string& where) {
  const json& v = member(obj, key, where);
  if (!v.is_number())
    fail(where + "." + key + " is not a number");
  const double d = v.get<double>();
  if (!std::isfinite(d))
    fail(where + "." + key + " is not finite");
  return d;
}

Eigen::Vector3d toVec(const json& v, const std::string& where) {
  if (!v.is_array() || v.size() != 3)
    fail(where + " is not an [x, y, z] array");
  Eigen::Vector3d out;
  for (int i = 0; i < 3; ++i) {
    if (!v[i].is_number())
      fail(where + " has a non-numeric coordinate");
    out[i] = v[i].get<double>();
  }
  if (!out.allFinite())
    fail(where + " is not finite");
  return out;
}

void checkFormat(const json& doc, const char* expected) {
  const auto it = doc.find("format");
  if (it == doc.end() || !it->is_string())
    fail(std::string("missing 'format' (expected '") + expected + "')");
  if (it->get<std::string>() != expected) {
    fail("format is '" + it->get<std::string>() + "', expected '" + expected + "'");
  }
  const auto units = doc.find("units");
  if (units != doc.end() && (!units->is_string() || units->get<std::string>() != "m")) {
    fail("units must be \"m\"");
  }
}

json parse(const std::string& text) {
  try {
    return json::parse(text);
  } catch (const json::exception& e) {
    // parse_error, and out_of_range for a number no double holds (1e499).
    fail(std::string("invalid JSON: ") + e.what());
  }
}

json cylinderJson(const modeling::CylinderModel& c, const Eigen::Vector3d& offset) {
  return json{{"id", c.id},
              {"center", vec(c.center + offset)},
              {"axis", vec(c.axis)},
              {"diameter", c.diameter},
              {"length", c.length},
              {"num_points", c.num_points},
              {"inlier_ratio", c.inlier_ratio}};
}

modeling::CylinderModel cylinderFromJson(const json& j, const std::string& where) {
  modeling::CylinderModel c;
  const json& id = member(j, "id", where);
  if (!id.is_number_integer())
    fail(where + ".id is not an integer");
  c.id = id.get<int>();
  c.center = toVec(member(j, "center", where), where + ".center");
  c.axis = toVec(member(j, "axis", where), where + ".axis");
  const double norm = c.axis.norm();
  if (norm < 1e-9)
    fail(where + ".axis is zero");
  c.axis /= norm;
  c.diameter = number(j, "diameter", where);
  if (c.diameter < 0.0)
    fail(where + ".diameter is negative");
  c.length = number(j, "length", where);
  if (c.length < 0.0)
    fail(where + ".length is negative");
  if (j.contains("num_points")) {
    const json& n = j.at("num_points");
    if (!n.is_number_integer() || n.get<long long>() < 0) {
      fail(where + ".num_points is not a non-negative integer");
    }
    c.num_points = n.get<std::size_t>();
  }
  if (j.contains("inlier_ratio") && j.at("inlier_ratio").is_number()) {
    c.inlier_ratio = j.at("inlier_ratio").get<double>();
  }
  return c;
}

json polylineJson(const evaluation::Polyline& p, bool with_id) {
  json points = json::array();
  for (const auto& q : p.points)
    points.push_back(vec(q));
  json j{{"points", points}, {"diameters", p.diameters}};
  if (with_id)
    j["id"] = p.id;
  return j;
}

evaluation::Polyline polylineFromJson(const json& j, const std::string& where, bool with_id) {
  evaluation::Polyline p;
  if (with_id) {
    const json& id = member(j, "id", where);
    if (!id.is_number_integer())
      fail(where + ".id is not an integer");
    p.id = id.get<int>();
  }
  const json& points = member(j, "points", where);
  const json& diameters = member(j, "diameters", where);
  if (!points.is_array())
    fail(where + ".points is not an array");
  if (!diameters.is_array())
    fail(where + ".diameters is not an array");
  if (points.size() != diameters.size()) {
    fail(where + " has " + std::to_string(points.size()) + " points but " +
         std::to_string(diameters.size()) + " diameters");
  }
  if (points.size() < 2)
    fail(where + " needs at least 2 points");
  for (std::size_t k = 0; k < points.size(); ++k) {
    p.points.push_back(toVec(points[k], where + ".points[" + std::to_string(k) + "]"));
    if (!diameters[k].is_number())
      fail(where + ".diameters[" + std::to_string(k) + "] is not a number");
    const double d = diameters[k].get<double>();
    if (!(d > 0.0) || !std::isfinite(d)) {
      fail(where + ".diameters[" + std::to_string(k) + "] must be positive");
    }
    p.diameters.push_back(d);
  }
  return p;
}

std::vector<evaluation::Polyline> polylinesFromJson(const json& doc, const char* key) {
  std::vector<evaluation::Polyline> out;
  const auto it = doc.find(key);
  if (it == doc.end())
    return out;
  if (!it->is_array())
    fail(std::string(key) + " is not an array");
  for (std::size_t i = 0; i < it->size(); ++i) {
    out.push_back(
        polylineFromJson((*it)[i], std::string(key) + "[" + std::to_string(i) + "]", true));
  }
  return out;
}

}  // namespace

namespace {

json correctionJson(const modeling::DiameterCorrection& c) {
  return {
      {"calibration", c.calibration.empty() ? json(nullptr) : json(c.calibration)},
      {"calibration_hash", c.calibration_hash.empty() ? json(nullptr) : json(c.calibration_hash)},
      {"noise_sigma_m", c.noise_sigma},
      {"table_noise_sigma_m", c.table_noise_sigma},
      {"search_noise_sigma_m", c.search_noise_sigma},
      {"warnings", c.warnings}};
}

/// The optional "diameter_correction" of a model document; absent in older files.
modeling::DiameterCorrection correctionFromJson(const json& doc) {
  modeling::DiameterCorrection c;
  if (!doc.contains("diameter_correction") || !doc["diameter_correction"].is_object())
    return c;
  const json& j = doc["diameter_correction"];
  if (j.contains("calibration") && j["calibration"].is_string())
    c.calibration = j["calibration"].get<std::string>();
  if (j.contains("calibration_hash") && j["calibration_hash"].is_string())
    c.calibration_hash = j["calibration_hash"].get<std::string>();
  if (j.contains("noise_sigma_m") && j["noise_sigma_m"].is_number())
    c.noise_sigma = j["noise_sigma_m"].get<double>();
  if (j.contains("table_noise_sigma_m") && j["table_noise_sigma_m"].is_number())
    c.table_noise_sigma = j["table_noise_sigma_m"].get<double>();
  if (j.contains("search_noise_sigma_m") && j["search_noise_sigma_m"].is_number())
    c.search_noise_sigma = j["search_noise_sigma_m"].get<double>();
  if (j.contains("warnings") && j["warnings"].is_array()) {
    for (const auto& w : j["warnings"]) {
      if (w.is_string())
        c.warnings.push_back(w.get<std::string>());
    }
  }
  return c;
}

}  // namespace

std::string modelToJson(const modeling::TreeModel& model, const Eigen::Vector3d& offset) {
  json trunk = json::array();
  for (const auto& c : model.trunk)
    trunk.push_back(cylinderJson(c, offset));
  json branches = json::array();
  for (const auto& b : model.primary_branches) {
    json j = cylinderJson(b.cylinder, offset);
    j["trunk_segment"] = b.trunk_segment;
    j["attachment_height"] = b.measurement.attachment_height;
    j["angle_to_trunk_deg"] = b.measurement.angle_to_trunk * RAD_TO_DEG;
    j["trunk_diameter"] = b.measurement.trunk_diameter;
    j["diameter_ratio"] = b.measurement.diameter_ratio;
    j["prune"] = b.measurement.prune;
    j["diameter_resolved"] = b.measurement.diameter_resolved;
    j["diameter_min"] = b.measurement.diameter_min;
    j["diameter_max"] = b.measurement.diameter_max;
    branches.push_back(j);
  }
  json doc{{"format", MODEL_FORMAT},
           {"units", "m"},
           {"input_points", model.input_points},
           {"trunk", trunk},
           {"primary_branches", branches},
           {"runtime_s", model.runtime_s},
           {"diameter_correction", correctionJson(model.correction)}};
  return doc.dump(2) + "\n";
}

namespace {

// A value of the wrong JSON type anywhere in a document ("id": "abc") is a parse error that
// names nlohmann's reason, not an exception of another type.
template <typename F>
auto guarded(F read) -> decltype(read()) {
  try {
    return read();
  } catch (const json::exception& e) {
    fail(std::string("invalid document: ") + e.what());
  }
}

modeling::TreeModel modelFromDocument(const std::string& text) {
  const json doc = parse(text);
  if (!doc.is_object())
    fail("model document is not a JSON object");
  checkFormat(doc, MODEL_FORMAT);
  modeling::TreeModel model;
  if (doc.contains("input_points") && doc["input_points"].is_number_integer()) {
    model.input_points = doc["input_points"].get<std::size_t>();
  }
  if (doc.contains("runtime_s") && doc["runtime_s"].is_number()) {
    model.runtime_s = doc["runtime_s"].get<double>();
  }
  const json& trunk = member(doc, "trunk", "model");
  if (!trunk.is_array())
    fail("trunk is not an array");
  for (std::size_t i = 0; i < trunk.size(); ++i) {
    model.trunk.push_back(cylinderFromJson(trunk[i], "trunk[" + std::to_string(i) + "]"));
  }
  const json& branches = member(doc, "primary_branches", "model");
  if (!branches.is_array())
    fail("primary_branches is not an array");
  for (std::size_t i = 0; i < branches.size(); ++i) {
    const std::string where = "primary_branches[" + std::to_string(i) + "]";
    modeling::PrimaryBranch b;
    b.cylinder = cylinderFromJson(branches[i], where);
    const json& j = branches[i];
    if (j.contains("trunk_segment") && j["trunk_segment"].is_number_integer()) {
      b.trunk_segment = j["trunk_segment"].get<int>();
    }
    if (j.contains("attachment_height") && j["attachment_height"].is_number()) {
      b.measurement.attachment_height = j["attachment_height"].get<double>();
    }
    if (j.contains("angle_to_trunk_deg") && j["angle_to_trunk_deg"].is_number()) {
      b.measurement.angle_to_trunk = j["angle_to_trunk_deg"].get<double>() / RAD_TO_DEG;
    }
    if (j.contains("trunk_diameter") && j["trunk_diameter"].is_number()) {
      b.measurement.trunk_diameter = j["trunk_diameter"].get<double>();
    }
    if (j.contains("diameter_ratio") && j["diameter_ratio"].is_number()) {
      b.measurement.diameter_ratio = j["diameter_ratio"].get<double>();
    }
    if (j.contains("prune") && j["prune"].is_boolean())
      b.measurement.prune = j["prune"].get<bool>();
    if (j.contains("diameter_resolved") && j["diameter_resolved"].is_boolean())
      b.measurement.diameter_resolved = j["diameter_resolved"].get<bool>();
    // Models written before the range was reported: the diameter is all they say.
    b.measurement.diameter_min = b.measurement.diameter_max = b.cylinder.diameter;
    if (j.contains("diameter_min") && j["diameter_min"].is_number())
      b.measurement.diameter_min = j["diameter_min"].get<double>();
    if (j.contains("diameter_max") && j["diameter_max"].is_number())
      b.measurement.diameter_max = j["diameter_max"].get<double>();
    model.primary_branches.push_back(b);
  }
  model.correction = correctionFromJson(doc);
  return model;
}

}  // namespace

modeling::TreeModel modelFromJson(const std::string& text) {
  return guarded([&] { return modelFromDocument(text); });
}

std::string truthToJson(const evaluation::GroundTruth& truth) {
  json primaries = json::array();
  for (const auto& p : truth.primary_branches)
    primaries.push_back(polylineJson(p, true));
  json minors = json::array();
  for (const auto& p : truth.minor_branches)
    minors.push_back(polylineJson(p, true));
  json doc{{"format", TRUTH_FORMAT},
           {"units", "m"},
           {"trunk", polylineJson(truth.trunk, false)},
           {"primary_branches", primaries},
           {"minor_branches", minors}};
  return doc.dump(1) + "\n";
}

namespace {

evaluation::GroundTruth truthFromDocument(const std::string& text) {
  const json doc = parse(text);
  if (!doc.is_object())
    fail("truth document is not a JSON object");
  checkFormat(doc, TRUTH_FORMAT);
  evaluation::GroundTruth truth;
  truth.trunk = polylineFromJson(member(doc, "trunk", "truth"), "trunk", false);
  truth.primary_branches = polylinesFromJson(doc, "primary_branches");
  truth.minor_branches = polylinesFromJson(doc, "minor_branches");
  return truth;
}

}  // namespace

evaluation::GroundTruth truthFromJson(const std::string& text) {
  return guarded([&] { return truthFromDocument(text); });
}

std::string readTextFile(const std::string& path) {
  std::error_code ec;
  if (!std::filesystem::is_regular_file(path, ec)) {
    throw Error(ErrorCode::FILE_NOT_FOUND, "no such file: " + path);
  }
  std::ifstream in(path, std::ios::binary);
  if (!in)
    throw Error(ErrorCode::IO_FAILURE, "cannot open " + path);
  std::ostringstream ss;
  ss << in.rdbuf();
  return ss.str();
}

void writeTextFile(const std::string& path, const std::string& text) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  if (!out)
    throw Error(ErrorCode::IO_FAILURE, "cannot write " + path);
  out << text;
  out.close();
  if (!out)
    throw Error(ErrorCode::IO_FAILURE, "write error in " + path);
}

namespace {

template <typename Parse>
auto parseFile(const std::string& path, Parse parse_fn) {
  const std::string text = readTextFile(path);
  try {
    return parse_fn(text);
  } catch (const Error& e) {
    throw Error(e.code(), path + ": " + e.what());
  }
}

}  // namespace

modeling::TreeModel readModelFile(const std::string& path) {
  return parseFile(path, modelFromJson);
}

evaluation::GroundTruth readTruthFile(const std::string& path) {
  return parseFile(path, truthFromJson);
}

}  // namespace io
}  // namespace dormant_tree_modeling
