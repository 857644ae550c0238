#include "dormant_tree_modeling/simulation/ray_caster.h"

#include <algorithm>
#include <cmath>
#include <numeric>

namespace dormant_tree_modeling {
namespace simulation {

namespace {

constexpr std::uint32_t LEAF_SIZE = 4;
constexpr double WIRE_PIECE_LENGTH = 1.0;  // m

bool slab(const Eigen::Vector3d& lo, const Eigen::Vector3d& hi, const Eigen::Vector3d& origin,
          const Eigen::Vector3d& inv_dir, double t_min, double t_max) {
  for (int i = 0; i < 3; ++i) {
    double t0 = (lo[i] - origin[i]) * inv_dir[i];
    double t1 = (hi[i] - origin[i]) * inv_dir[i];
    if (t0 > t1)
      std::swap(t0, t1);
    t_min = std::max(t_min, t0);
    t_max = std::min(t_max, t1);
    if (t_max < t_min)
      return false;
  }
  return true;
}

}  // namespace

void RayCaster::addPolyline(const BranchPolyline& b, std::uint16_t object, std::uint16_t index,
                            float refl) {
  const Label label{object, b.part, index};
  for (std::size_t i = 0; i + 1 < b.points.size(); ++i) {
    Prim p{};
    p.is_sphere = false;
    p.frustum = Frustum{b.points[i], b.points[i + 1], b.radii[i], b.radii[i + 1]};
    p.label = label;
    p.reflectivity = refl;
    prims_.push_back(p);
    if (i > 0) {
      Prim s{};
      s.is_sphere = true;
      s.sphere = Sphere{b.points[i], b.radii[i]};
      s.label = label;
      s.reflectivity = refl;
      prims_.push_back(s);
    }
  }
}

RayCaster::RayCaster(const Scene& scene)
    : has_ground_(scene.has_ground),
      ground_z_(scene.ground_z),
      ground_half_extent_(scene.ground_half_extent),
      ground_reflectivity_(static_cast<float>(scene.reflectances.ground)) {
  const auto bark = static_cast<float>(scene.reflectances.bark);
  for (std::size_t t = 0; t < scene.trees.size(); ++t) {
    for (std::size_t i = 0; i < scene.trees[t].branches.size(); ++i) {
      addPolyline(scene.trees[t].branches[i], static_cast<std::uint16_t>(t),
                  static_cast<std::uint16_t>(i), bark);
    }
  }
  std::uint16_t object = static_cast<std::uint16_t>(scene.trees.size());
  for (const auto& w : scene.wires) {
    const double length = (w.b - w.a).norm();
    const int pieces = std::max(1, static_cast<int>(std::ceil(length / WIRE_PIECE_LENGTH)));
    BranchPolyline line;
    line.part = Part::WIRE;
    for (int i = 0; i <= pieces; ++i) {
      line.points.push_back(w.a + (w.b - w.a) * (static_cast<double>(i) / pieces));
      line.radii.push_back(w.radius);
    }
    addPolyline(line, object++, 0, static_cast<float>(scene.reflectances.wire));
  }
  for (const auto& p : scene.posts) {
    BranchPolyline line;
    line.part = Part::POST;
    line.points = {p.base, p.base + Eigen::Vector3d(0, 0, p.height)};
    line.radii = {p.radius, p.radius};
    addPolyline(line, object, 0, static_cast<float>(scene.reflectances.post));
    Prim cap{};  // flat-ish top: a sphere of the post's radius
    cap.is_sphere = true;
    cap.sphere = Sphere{line.points[1], p.radius};
    cap.label = Label{object, Part::POST, 0};
    cap.reflectivity = static_cast<float>(scene.reflectances.post);
    prims_.push_back(cap);
    ++object;
  }
  prim_lo_.resize(prims_.size());
  prim_hi_.resize(prims_.size());
  for (std::size_t i = 0; i < prims_.size(); ++i) {
    const Prim& p = prims_[i];
    if (p.is_sphere) {
      prim_lo_[i] = p.sphere.c.array() - p.sphere.r;
      prim_hi_[i] = p.sphere.c.array() + p.sphere.r;
    } else {
      const double r = std::max(p.frustum.ra, p.frustum.rb);
      prim_lo_[i] = p.frustum.a.cwiseMin(p.frustum.b).array() - r;
      prim_hi_[i] = p.frustum.a.cwiseMax(p.frustum.b).array() + r;
    }
  }
  if (!prims_.empty()) {
    nodes_.reserve(2 * prims_.size() / LEAF_SIZE + 2);
    build(0, static_cast<std::uint32_t>(prims_.size()), 0);
  }
}

std::uint32_t RayCaster::build(std::uint32_t begin, std::uint32_t end, int depth) {
  const std::uint32_t index = static_cast<std::uint32_t>(nodes_.size());
  nodes_.push_back(Node{});
  Eigen::Vector3d lo = prim_lo_[begin], hi = prim_hi_[begin];
  Eigen::Vector3d clo = 0.5 * (prim_lo_[begin] + prim_hi_[begin]), chi = clo;
  for (std::uint32_t i = begin; i < end; ++i) {
    lo = lo.cwiseMin(prim_lo_[i]);
    hi = hi.cwiseMax(prim_hi_[i]);
    const Eigen::Vector3d c = 0.5 * (prim_lo_[i] + prim_hi_[i]);
    clo = clo.cwiseMin(c);
    chi = chi.cwiseMax(c);
  }
  nodes_[index].lo = lo;
  nodes_[index].hi = hi;
  if (end - begin <= LEAF_SIZE || depth > 48) {
    nodes_[index].first = begin;
    nodes_[index].count = end - begin;
    return index;
  }
  int axis = 0;
  (chi - clo).maxCoeff(&axis);
  const std::uint32_t mid = begin + (end - begin) / 2;
  // Median split on box centres; permute all three parallel arrays together.
  std::vector<std::uint32_t> order(end - begin);
  std::iota(order.begin(), order.end(), begin);
  std::nth_element(order.begin(), order.begin() + (mid - begin), order.end(),
                   [&](std::uint32_t a, std::uint32_t b) {
                     return prim_lo_[a][axis] + prim_hi_[a][axis] <
                            prim_lo_[b][axis] + prim_hi_[b][axis];
                   });
  std::vector<Prim> p(order.size());
  std::vector<Eigen::Vector3d> l(order.size()), h(order.size());
  for (std::size_t i = 0; i < order.size(); ++i) {
    p[i] = prims_[order[i]];
    l[i] = prim_lo_[order[i]];
    h[i] = prim_hi_[order[i]];
  }
  std::copy(p.begin(), p.end(), prims_.begin() + begin);
  std::copy(l.begin(), l.end(), prim_lo_.begin() + begin);
  std::copy(h.begin(), h.end(), prim_hi_.begin() + begin);
  const std::uint32_t left = build(begin, mid, depth + 1);
  const std::uint32_t right = build(mid, end, depth + 1);
  nodes_[index].first = left;
  nodes_[index].count = 0;
  nodes_[index].right = right;
  return index;
}

std::optional<Hit> RayCaster::cast(const Ray& ray, double t_min, double t_max) const {
  std::optional<Hit> best;
  double best_t = t_max;
  if (has_ground_ && ray.direction.z() < 0.0) {
    const double t = (ground_z_ - ray.origin.z()) / ray.direction.z();
    if (t > t_min && t < best_t) {
      const Eigen::Vector3d p = ray.origin + t * ray.direction;
      if (std::abs(p.x()) <= ground_half_extent_ && std::abs(p.y()) <= ground_half_extent_) {
        best_t = t;
        best =
            Hit{t, Eigen::Vector3d::UnitZ(), Label{0xffff, Part::GROUND, 0}, ground_reflectivity_};
      }
    }
  }
  if (nodes_.empty())
    return best;
  const Eigen::Vector3d inv_dir = ray.direction.cwiseInverse();
  std::uint32_t stack[128];
  int top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const Node& node = nodes_[stack[--top]];
    if (!slab(node.lo, node.hi, ray.origin, inv_dir, t_min, best_t))
      continue;
    if (node.count == 0) {
      stack[top++] = node.first;
      stack[top++] = node.right;
      continue;
    }
    for (std::uint32_t i = node.first; i < node.first + node.count; ++i) {
      const Prim& p = prims_[i];
      const auto hit = p.is_sphere ? intersect(ray, p.sphere, t_min, best_t)
                                   : intersect(ray, p.frustum, t_min, best_t);
      if (hit) {
        best_t = hit->first;
        best = Hit{hit->first, hit->second, p.label, p.reflectivity};
      }
    }
  }
  return best;
}

}  // namespace simulation
}  // namespace dormant_tree_modeling
