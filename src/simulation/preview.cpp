#include "dormant_tree_modeling/simulation/preview.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <stb/stb_image_write.h>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <vector>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace simulation {

namespace {

// A preview frames a tree: a model wider or taller than this is not one.
constexpr double MAX_PREVIEW_SPAN_M = 100.0;
// The picture is at most this many times as tall as wide.
constexpr int MAX_ASPECT = 4;
// Longest line drawn, pixels (a few canvas diagonals).
constexpr double MAX_LINE_PIXELS = 1e5;

struct Canvas {
  int w, h;
  std::vector<std::uint8_t> rgb;
  Canvas(int width, int height)
      : w(width), h(height), rgb(static_cast<std::size_t>(width) * height * 3, 255) {}
  bool inside(double x, double y, double margin = 0.0) const {
    return x >= -margin && y >= -margin && x < w + margin && y < h + margin;
  }
  // Takes doubles: a pixel coordinate far outside the canvas must not be cast to int.
  void put(double x, double y, const std::uint8_t c[3]) {
    if (!inside(x, y))
      return;
    const auto xi = static_cast<std::size_t>(x), yi = static_cast<std::size_t>(y);
    std::copy(c, c + 3, &rgb[(yi * w + xi) * 3]);
  }
  void disc(double cx, double cy, double r, const std::uint8_t c[3]) {
    if (!inside(cx, cy, r + 1.0))
      return;
    const int ri = static_cast<int>(std::ceil(r));
    for (int dy = -ri; dy <= ri; ++dy)
      for (int dx = -ri; dx <= ri; ++dx)
        if (dx * dx + dy * dy <= r * r + 0.5)
          put(std::floor(cx) + dx, std::floor(cy) + dy, c);
  }
  void line(double x0, double y0, double x1, double y1, double r, const std::uint8_t c[3]) {
    const double length = std::hypot(x1 - x0, y1 - y0);
    if (!std::isfinite(length) || length > MAX_LINE_PIXELS)
      return;  // a segment no tree has; the canvas is sized to the model, not to it
    const int steps = static_cast<int>(std::ceil(length)) + 1;
    for (int i = 0; i <= steps; ++i) {
      const double t = static_cast<double>(i) / steps;
      disc(x0 + t * (x1 - x0), y0 + t * (y1 - y0), r, c);
    }
  }
};

}  // namespace

namespace {

/// A front-view canvas (x right, z up) framed on a box, with the cloud drawn in grey.
struct FrontView {
  Eigen::Vector2d lo, hi;
  double scale = 1.0;
  int height = 1;
  Canvas canvas{1, 1};

  FrontView(const Cloud& cloud, Eigen::Vector2d box_lo, Eigen::Vector2d box_hi, int width) {
    lo = box_lo - Eigen::Vector2d(0.3, 0.1);
    hi = box_hi + Eigen::Vector2d(0.3, 0.2);
    lo.y() = std::min(lo.y(), 0.0);
    const Eigen::Vector2d span = hi - lo;
    if (!span.allFinite() || span.maxCoeff() > MAX_PREVIEW_SPAN_M) {
      throw Error(ErrorCode::INVALID_ARGUMENT, "the model spans " + std::to_string(span.x()) +
                                                   " m x " + std::to_string(span.y()) +
                                                   " m, not a tree: nothing rendered");
    }
    scale = width / span.x();
    height = std::clamp(static_cast<int>(span.y() * scale), 1, MAX_ASPECT * width);
    canvas = Canvas(width, height);
    // Points: darker when nearer the viewer (smaller y), so depth reads at a glance.
    for (const auto& p : cloud.points) {
      const double shade = std::clamp(60.0 + 40.0 * (p.y + 1.5), 40.0, 200.0);
      const std::uint8_t c[3] = {static_cast<std::uint8_t>(shade), static_cast<std::uint8_t>(shade),
                                 static_cast<std::uint8_t>(shade)};
      canvas.put(px(p.x), py(p.z), c);
    }
  }
  double px(double x) const { return (x - lo.x()) * scale; }
  double py(double z) const { return height - 1 - (z - lo.y()) * scale; }
  void segment(const Eigen::Vector3d& a, const Eigen::Vector3d& b, double diameter,
               const std::uint8_t c[3]) {
    canvas.line(px(a.x()), py(a.z()), px(b.x()), py(b.z()), std::max(1.0, 0.5 * diameter * scale),
                c);
  }
  void save(const std::string& path) const {
    if (!stbi_write_png(path.c_str(), canvas.w, canvas.h, 3, canvas.rgb.data(), canvas.w * 3)) {
      throw Error(ErrorCode::IO_FAILURE, "cannot write " + path);
    }
  }
};

const std::uint8_t BROWN[3] = {140, 80, 20};
const std::uint8_t GREEN[3] = {20, 170, 40};
const std::uint8_t RED[3] = {220, 30, 30};

}  // namespace

void renderPreview(const Cloud& cloud, const evaluation::GroundTruth& truth,
                   const std::string& path, int width) {
  Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
  auto grow = [&](const evaluation::Polyline& p) {
    for (const auto& q : p.points) {
      lo = lo.cwiseMin(Eigen::Vector2d(q.x(), q.z()));
      hi = hi.cwiseMax(Eigen::Vector2d(q.x(), q.z()));
    }
  };
  grow(truth.trunk);
  for (const auto& b : truth.primary_branches)
    grow(b);
  FrontView view(cloud, lo, hi, width);
  auto draw = [&](const evaluation::Polyline& p, const std::uint8_t c[3]) {
    for (std::size_t i = 0; i + 1 < p.points.size(); ++i)
      view.segment(p.points[i], p.points[i + 1], p.diameters[i], c);
  };
  for (const auto& b : truth.primary_branches)
    draw(b, GREEN);
  draw(truth.trunk, BROWN);
  view.save(path);
}

void renderModelPreview(const Cloud& cloud, const modeling::TreeModel& model,
                        const std::string& path, int width) {
  Eigen::Vector2d lo(1e9, 1e9), hi(-1e9, -1e9);
  auto ends = [](const modeling::CylinderModel& c) {
    return std::make_pair(Eigen::Vector3d(c.center - 0.5 * c.length * c.axis),
                          Eigen::Vector3d(c.center + 0.5 * c.length * c.axis));
  };
  auto grow = [&](const modeling::CylinderModel& c) {
    for (const auto& e : {ends(c).first, ends(c).second}) {
      lo = lo.cwiseMin(Eigen::Vector2d(e.x(), e.z()));
      hi = hi.cwiseMax(Eigen::Vector2d(e.x(), e.z()));
    }
  };
  for (const auto& c : model.trunk)
    grow(c);
  for (const auto& b : model.primary_branches)
    grow(b.cylinder);
  if (lo.x() > hi.x())
    throw Error(ErrorCode::INVALID_ARGUMENT, "empty model: nothing to render");
  FrontView view(cloud, lo, hi, width);
  for (const auto& b : model.primary_branches) {
    const auto e = ends(b.cylinder);
    view.segment(e.first, e.second, b.cylinder.diameter, b.measurement.prune ? RED : GREEN);
  }
  for (const auto& c : model.trunk) {
    const auto e = ends(c);
    view.segment(e.first, e.second, c.diameter, BROWN);
  }
  view.save(path);
}

void writeRangePgm(const std::string& path, int rows, int cols, const float* ranges_m) {
  std::ofstream f(path, std::ios::binary | std::ios::trunc);
  if (!f)
    throw Error(ErrorCode::IO_FAILURE, "cannot write " + path);
  f << "P5\n" << cols << " " << rows << "\n65535\n";
  for (std::size_t i = 0; i < static_cast<std::size_t>(rows) * cols; ++i) {
    const long mm = std::clamp(std::lround(ranges_m[i] * 1000.0), 0L, 65535L);
    const char be[2] = {static_cast<char>((mm >> 8) & 0xff), static_cast<char>(mm & 0xff)};
    f.write(be, 2);
  }
  if (!f)
    throw Error(ErrorCode::IO_FAILURE, "write error in " + path);
}

}  // namespace simulation
}  // namespace dormant_tree_modeling
