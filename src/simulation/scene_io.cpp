#include <nlohmann/json.hpp>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/io/tree_json.h"
#include "dormant_tree_modeling/simulation/scene.h"

namespace dormant_tree_modeling {
namespace simulation {

using nlohmann::json;

namespace {

constexpr const char* SCENE_FORMAT = "dormant_tree_scene/1";

const char* partName(Part p) {
  switch (p) {
    case Part::TRUNK:
      return "trunk";
    case Part::PRIMARY:
      return "primary";
    case Part::SECONDARY:
      return "secondary";
    case Part::MINOR:
      return "minor";
    case Part::WIRE:
      return "wire";
    case Part::POST:
      return "post";
    case Part::GROUND:
      return "ground";
    case Part::NONE:
      break;
  }
  return "none";
}

Part partFromName(const std::string& s) {
  for (Part p : {Part::TRUNK, Part::PRIMARY, Part::SECONDARY, Part::MINOR, Part::WIRE, Part::POST,
                 Part::GROUND}) {
    if (s == partName(p))
      return p;
  }
  throw Error(ErrorCode::PARSE_ERROR, "unknown part '" + s + "' in scene");
}

json vec(const Eigen::Vector3d& v) {
  return json::array({v.x(), v.y(), v.z()});
}

Eigen::Vector3d toVec(const json& j) {
  if (!j.is_array() || j.size() != 3)
    throw Error(ErrorCode::PARSE_ERROR, "scene: bad vector");
  return Eigen::Vector3d(j[0].get<double>(), j[1].get<double>(), j[2].get<double>());
}

}  // namespace

void saveScene(const Scene& scene, const std::string& path) {
  json trees = json::array();
  for (const auto& t : scene.trees) {
    json branches = json::array();
    for (const auto& b : t.branches) {
      json vertices = json::array();
      for (std::size_t i = 0; i < b.points.size(); ++i) {
        vertices.push_back({b.points[i].x(), b.points[i].y(), b.points[i].z(), b.radii[i]});
      }
      branches.push_back(
          {{"part", partName(b.part)}, {"parent", b.parent}, {"vertices", vertices}});
    }
    trees.push_back({{"preset", t.preset}, {"seed", t.seed}, {"branches", branches}});
  }
  json wires = json::array();
  for (const auto& w : scene.wires)
    wires.push_back({{"a", vec(w.a)}, {"b", vec(w.b)}, {"radius", w.radius}});
  json posts = json::array();
  for (const auto& p : scene.posts) {
    posts.push_back({{"base", vec(p.base)}, {"height", p.height}, {"radius", p.radius}});
  }
  const json doc{{"format", SCENE_FORMAT},
                 {"units", "m"},
                 {"trees", trees},
                 {"wires", wires},
                 {"posts", posts},
                 {"ground",
                  {{"enabled", scene.has_ground},
                   {"z", scene.ground_z},
                   {"half_extent", scene.ground_half_extent}}},
                 {"reflectances",
                  {{"bark", scene.reflectances.bark},
                   {"wire", scene.reflectances.wire},
                   {"post", scene.reflectances.post},
                   {"ground", scene.reflectances.ground}}}};
  io::writeTextFile(path, doc.dump() + "\n");
}

Scene loadScene(const std::string& path) {
  const std::string text = io::readTextFile(path);
  try {
    const json doc = json::parse(text);
    if (doc.value("format", "") != SCENE_FORMAT) {
      throw Error(ErrorCode::PARSE_ERROR,
                  "not a scene file (format is not " + std::string(SCENE_FORMAT) + ")");
    }
    Scene scene;
    for (const auto& t : doc.at("trees")) {
      TreeObject tree;
      tree.preset = t.value("preset", "");
      tree.seed = t.value("seed", std::uint64_t{0});
      for (const auto& b : t.at("branches")) {
        BranchPolyline line;
        line.part = partFromName(b.at("part").get<std::string>());
        line.parent = b.value("parent", -1);
        for (const auto& v : b.at("vertices")) {
          if (!v.is_array() || v.size() != 4)
            throw Error(ErrorCode::PARSE_ERROR, "bad vertex");
          line.points.emplace_back(v[0].get<double>(), v[1].get<double>(), v[2].get<double>());
          line.radii.push_back(v[3].get<double>());
        }
        if (line.points.size() < 2)
          throw Error(ErrorCode::PARSE_ERROR, "polyline with < 2 vertices");
        tree.branches.push_back(std::move(line));
      }
      scene.trees.push_back(std::move(tree));
    }
    for (const auto& w : doc.at("wires")) {
      scene.wires.push_back(Wire{toVec(w.at("a")), toVec(w.at("b")), w.at("radius").get<double>()});
    }
    for (const auto& p : doc.at("posts")) {
      scene.posts.push_back(
          Post{toVec(p.at("base")), p.at("height").get<double>(), p.at("radius").get<double>()});
    }
    const auto& g = doc.at("ground");
    scene.has_ground = g.at("enabled").get<bool>();
    scene.ground_z = g.at("z").get<double>();
    scene.ground_half_extent = g.at("half_extent").get<double>();
    const auto& r = doc.at("reflectances");
    scene.reflectances = Reflectances{r.at("bark").get<double>(), r.at("wire").get<double>(),
                                      r.at("post").get<double>(), r.at("ground").get<double>()};
    return scene;
  } catch (const json::exception& e) {
    throw Error(ErrorCode::PARSE_ERROR, path + ": malformed scene: " + e.what());
  } catch (const Error& e) {
    throw Error(e.code(), path + ": " + e.what());
  }
}

}  // namespace simulation
}  // namespace dormant_tree_modeling
