#include "dormant_tree_modeling/simulation/tree_generator.h"

#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>

#include "dormant_tree_modeling/common/random.h"

namespace dormant_tree_modeling {
namespace simulation {

namespace {

constexpr double DEG = M_PI / 180.0;
constexpr double MIN_BRANCH_HEIGHT = 0.03;  // m above ground: branches rest on it, not below
constexpr double SECONDARY_MAX_DIAMETER = 0.006;
constexpr double SPUR_MIN_DIAMETER = 0.004, SPUR_MAX_DIAMETER = 0.007;

double polylineLength(const std::vector<Eigen::Vector3d>& pts) {
  double l = 0.0;
  for (std::size_t i = 1; i < pts.size(); ++i)
    l += (pts[i] - pts[i - 1]).norm();
  return l;
}

/// Unit vector orthogonal to `t`, as close as possible to horizontal direction `azimuth`.
Eigen::Vector3d sideways(const Eigen::Vector3d& t, double azimuth) {
  Eigen::Vector3d h(std::cos(azimuth), std::sin(azimuth), 0.0);
  h -= h.dot(t) * t;
  if (h.norm() < 1e-6)
    h = t.unitOrthogonal();
  return h.normalized();
}

/// Grows a woody axis from `start` with initial direction `dir`: it bends towards the ground
/// at `droop` rad/m (weighted by how horizontal it is), wiggles a little, tapers linearly.
BranchPolyline growAxis(Part part, int parent, const Eigen::Vector3d& start, Eigen::Vector3d dir,
                        double length, double r0, double r1, double droop, double step, Rng& rng) {
  BranchPolyline b;
  b.part = part;
  b.parent = parent;
  const int n = std::max(2, static_cast<int>(std::ceil(length / step)));
  const double ds = length / n;
  Eigen::Vector3d p = start;
  b.points.push_back(p);
  b.radii.push_back(r0);
  for (int i = 1; i <= n; ++i) {
    // Gravity: rotate towards -z about the horizontal axis perpendicular to dir.
    Eigen::Vector3d axis = dir.cross(Eigen::Vector3d::UnitZ());
    if (axis.norm() > 1e-6) {
      const double bend = droop * ds + rng.normal(0.0, 1.5 * DEG);
      dir = Eigen::AngleAxisd(bend, axis.normalized()) * dir;
    }
    const Eigen::Vector3d wiggle_axis = dir.unitOrthogonal();
    dir = Eigen::AngleAxisd(rng.normal(0.0, 1.5 * DEG), wiggle_axis) * dir;
    dir.normalize();
    p += ds * dir;
    p.z() = std::max(p.z(), MIN_BRANCH_HEIGHT);
    b.points.push_back(p);
    b.radii.push_back(r0 + (r1 - r0) * static_cast<double>(i) / n);
  }
  return b;
}

/// Index of the vertex of `pts` nearest to arc length `s` from the start.
std::size_t vertexAtLength(const std::vector<Eigen::Vector3d>& pts, double s) {
  double acc = 0.0;
  for (std::size_t i = 1; i < pts.size(); ++i) {
    acc += (pts[i] - pts[i - 1]).norm();
    if (acc >= s)
      return i;
  }
  return pts.size() - 1;
}

Eigen::Vector3d tangentAt(const std::vector<Eigen::Vector3d>& pts, std::size_t i) {
  const std::size_t a = i == 0 ? 0 : i - 1;
  const std::size_t b = std::min(pts.size() - 1, i + 1);
  return (pts[b] - pts[a]).normalized();
}

BranchPolyline makeTrunk(const TreeConfig& p, const Eigen::Vector3d& base, double height,
                         Rng& rng) {
  const double lean = rng.uniform(0.0, p.lean_max_deg) * DEG;
  const double lean_azimuth = rng.uniform(0.0, 2.0 * M_PI);
  const Eigen::Vector3d up(std::sin(lean) * std::cos(lean_azimuth),
                           std::sin(lean) * std::sin(lean_azimuth), std::cos(lean));
  const double ax = rng.uniform(0.0, p.bend_amplitude_max);
  const double ay = rng.uniform(0.0, p.bend_amplitude_max);
  const double lx = rng.uniform(1.0, 3.0), ly = rng.uniform(1.0, 3.0);
  const double px = rng.uniform(0.0, 2.0 * M_PI), py = rng.uniform(0.0, 2.0 * M_PI);
  const double r0 = 0.5 * rng.uniform(p.base_diameter_min, p.base_diameter_max);
  const double r1 = 0.5 * p.top_diameter;
  const double shape = rng.uniform(0.7, 1.0);
  BranchPolyline trunk;
  trunk.part = Part::TRUNK;
  const int n = std::max(2, static_cast<int>(std::ceil(height / p.segment_length)));
  for (int i = 0; i <= n; ++i) {
    const double s = height * i / n;
    const double f = s / height;
    // Sway grows from zero at the ground, so the base stays where it was planted.
    const Eigen::Vector3d sway(ax * f * std::sin(2.0 * M_PI * s / lx + px),
                               ay * f * std::sin(2.0 * M_PI * s / ly + py), 0.0);
    trunk.points.push_back(base + s * up + sway);
    trunk.radii.push_back(r0 + (r1 - r0) * std::pow(f, shape));
  }
  return trunk;
}

void addShoots(TreeObject& tree, int parent, const TreeConfig& p, Rng& rng) {
  const BranchPolyline primary = tree.branches[parent];  // copy: branches grows below
  const double length = polylineLength(primary.points);
  const double trunk_clearance = 0.06;
  auto place = [&](double& s, std::size_t& k) {
    s = rng.uniform(std::min(trunk_clearance + 0.1 * length, 0.9 * length), 0.95 * length);
    k = vertexAtLength(primary.points, s);
  };
  const int secondaries =
      static_cast<int>(std::round(p.secondaries_per_m * length * rng.uniform(0.5, 1.5)));
  for (int i = 0; i < secondaries; ++i) {
    double s;
    std::size_t k;
    place(s, k);
    const Eigen::Vector3d t = tangentAt(primary.points, k);
    const double local_d = 2.0 * primary.radii[k];
    const double d = std::min(
        {SECONDARY_MAX_DIAMETER, 0.6 * local_d, rng.uniform(0.0025, SECONDARY_MAX_DIAMETER)});
    const Eigen::Vector3d side = t.unitOrthogonal();
    Eigen::Vector3d dir = Eigen::AngleAxisd(rng.uniform(0.0, 2.0 * M_PI), t) * side *
                              std::sin(rng.uniform(40, 80) * DEG) +
                          t * std::cos(60.0 * DEG);
    dir = (dir.normalized() + Eigen::Vector3d(0, 0, rng.uniform(0.2, 0.8))).normalized();
    tree.branches.push_back(growAxis(Part::SECONDARY, parent, primary.points[k], dir,
                                     rng.uniform(0.05, 0.3), 0.5 * d, 0.4 * p.tip_diameter, 0.0,
                                     0.03, rng));
  }
  const int spurs = static_cast<int>(std::round(p.spurs_per_m * length * rng.uniform(0.5, 1.5)));
  for (int i = 0; i < spurs; ++i) {
    double s;
    std::size_t k;
    place(s, k);
    const Eigen::Vector3d t = tangentAt(primary.points, k);
    const double d =
        std::min(2.0 * primary.radii[k], rng.uniform(SPUR_MIN_DIAMETER, SPUR_MAX_DIAMETER));
    const Eigen::Vector3d dir =
        Eigen::AngleAxisd(rng.uniform(0.0, 2.0 * M_PI), t) * t.unitOrthogonal();
    tree.branches.push_back(growAxis(Part::SECONDARY, parent, primary.points[k], dir,
                                     rng.uniform(0.01, 0.05), 0.5 * d, 0.35 * d, 0.0, 0.02, rng));
  }
}

}  // namespace

TreeObject generateTree(const TreeConfig& p, std::uint64_t seed, const Eigen::Vector3d& base,
                        double azimuth_offset) {
  Rng rng(seed);
  TreeObject tree;
  tree.preset = p.preset;
  tree.seed = seed;
  const double height = rng.uniform(p.height_min, p.height_max);
  tree.branches.push_back(makeTrunk(p, base, height, rng));
  const BranchPolyline trunk = tree.branches[0];

  const int count = rng.uniformInt(p.primaries_min, p.primaries_max);
  const double h0 = rng.uniform(p.first_branch_min, p.first_branch_max);
  const double h1 = p.top_branch_fraction * height;
  const double golden = M_PI * (3.0 - std::sqrt(5.0));
  const double azimuth0 = azimuth_offset + rng.uniform(0.0, 2.0 * M_PI);
  std::vector<int> primaries;
  for (int i = 0; i < count; ++i) {
    const double f = count > 1 ? static_cast<double>(i) / (count - 1) : 0.0;
    const double spacing = (h1 - h0) / std::max(1, count - 1);
    const double s = std::clamp(h0 + f * (h1 - h0) + rng.uniform(-0.3, 0.3) * spacing, h0, h1);
    const std::size_t k = vertexAtLength(trunk.points, s);
    const Eigen::Vector3d t = tangentAt(trunk.points, k);
    const double trunk_d = 2.0 * trunk.radii[k];
    const bool large = rng.bernoulli(p.large_ratio_fraction);
    const double ratio = large ? rng.uniform(0.55, 0.8) : rng.uniform(p.ratio_min, p.ratio_max);
    double d = std::clamp(ratio * trunk_d, p.primary_diameter_min, p.primary_diameter_max);
    d = std::max(PRIMARY_MIN_BASE_DIAMETER, std::min(d, 0.85 * trunk_d));
    // Conical crown: branches are longer low on the tree.
    const double cone = 1.0 - 0.6 * (s - h0) / std::max(1e-6, h1 - h0);
    const double length =
        std::max(PRIMARY_MIN_LENGTH + 0.05,
                 cone * rng.uniform(p.branch_length_min, p.branch_length_max) + 0.5 * trunk_d);
    const double azimuth = azimuth0 + i * golden + rng.uniform(-25.0, 25.0) * DEG;
    const double elevation = rng.uniform(p.elevation_min_deg, p.elevation_max_deg) * DEG;
    const Eigen::Vector3d dir =
        std::cos(elevation) * sideways(t, azimuth) + std::sin(elevation) * t;
    const double droop = rng.uniform(0.5, 1.5) * p.droop_deg_per_m * DEG;
    tree.branches.push_back(growAxis(Part::PRIMARY, 0, trunk.points[k], dir, length, 0.5 * d,
                                     0.5 * p.tip_diameter, droop, p.segment_length, rng));
    primaries.push_back(static_cast<int>(tree.branches.size()) - 1);
  }
  for (const int b : primaries)
    addShoots(tree, b, p, rng);

  // Shoots and stubs on the trunk: too thin or too short to be primaries (docs/evaluation.md).
  const int shoots = rng.uniformInt(p.trunk_shoots_min, p.trunk_shoots_max);
  for (int i = 0; i < shoots; ++i) {
    const double s = rng.uniform(0.25, 0.95) * height;
    const std::size_t k = vertexAtLength(trunk.points, s);
    const Eigen::Vector3d t = tangentAt(trunk.points, k);
    const bool stub = i == 0 && rng.bernoulli(0.5);
    const double d =
        stub ? rng.uniform(PRIMARY_MIN_BASE_DIAMETER, 0.015) : rng.uniform(0.003, 0.007);
    const double length = trunk.radii[k] + (stub ? rng.uniform(0.03, 0.1) : rng.uniform(0.05, 0.3));
    const double elevation = rng.uniform(20.0, 70.0) * DEG;
    const Eigen::Vector3d dir =
        std::cos(elevation) * sideways(t, rng.uniform(0.0, 2.0 * M_PI)) + std::sin(elevation) * t;
    const double grown = stub ? std::min(length, PRIMARY_MIN_LENGTH - 0.01) : length;
    tree.branches.push_back(growAxis(Part::MINOR, 0, trunk.points[k], dir, grown, 0.5 * d,
                                     stub ? 0.45 * d : 0.0015, 0.0, 0.03, rng));
  }
  return tree;
}

evaluation::GroundTruth truthFromTree(const TreeObject& tree) {
  evaluation::GroundTruth truth;
  auto toPolyline = [](const BranchPolyline& b, int id) {
    evaluation::Polyline out;
    out.id = id;
    out.points = b.points;
    for (const double r : b.radii)
      out.diameters.push_back(2.0 * r);
    return out;
  };
  for (std::size_t i = 0; i < tree.branches.size(); ++i) {
    const auto& b = tree.branches[i];
    if (b.part == Part::TRUNK && b.parent < 0) {
      truth.trunk = toPolyline(b, -1);
    } else if (b.part == Part::PRIMARY || b.part == Part::MINOR) {
      const bool primary = 2.0 * b.radii.front() >= PRIMARY_MIN_BASE_DIAMETER &&
                           polylineLength(b.points) >= PRIMARY_MIN_LENGTH;
      auto& list = primary ? truth.primary_branches : truth.minor_branches;
      list.push_back(toPolyline(b, static_cast<int>(i)));
    }
  }
  return truth;
}

}  // namespace simulation
}  // namespace dormant_tree_modeling
