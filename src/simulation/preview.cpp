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

struct Canvas {
  int w, h;
  std::vector<std::uint8_t> rgb;
  Canvas(int width, int height)
      : w(width), h(height), rgb(static_cast<std::size_t>(width) * height * 3, 255) {}
  void put(int x, int y, const std::uint8_t c[3]) {
    if (x < 0 || y < 0 || x >= w || y >= h)
      return;
    std::copy(c, c + 3, &rgb[(static_cast<std::size_t>(y) * w + x) * 3]);
  }
  void disc(double cx, double cy, double r, const std::uint8_t c[3]) {
    const int ri = static_cast<int>(std::ceil(r));
    for (int dy = -ri; dy <= ri; ++dy)
      for (int dx = -ri; dx <= ri; ++dx)
        if (dx * dx + dy * dy <= r * r + 0.5)
          put(static_cast<int>(cx) + dx, static_cast<int>(cy) + dy, c);
  }
  void line(double x0, double y0, double x1, double y1, double r, const std::uint8_t c[3]) {
    const int steps = static_cast<int>(std::ceil(std::hypot(x1 - x0, y1 - y0))) + 1;
    for (int i = 0; i <= steps; ++i) {
      const double t = static_cast<double>(i) / steps;
      disc(x0 + t * (x1 - x0), y0 + t * (y1 - y0), r, c);
    }
  }
};

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
  lo -= Eigen::Vector2d(0.3, 0.1);
  hi += Eigen::Vector2d(0.3, 0.2);
  lo.y() = std::min(lo.y(), 0.0);
  const double scale = width / (hi.x() - lo.x());
  const int height = std::max(1, static_cast<int>((hi.y() - lo.y()) * scale));
  Canvas canvas(width, height);
  auto px = [&](double x) { return (x - lo.x()) * scale; };
  auto py = [&](double z) { return height - 1 - (z - lo.y()) * scale; };
  // Points: darker when nearer the viewer (smaller y), so depth reads at a glance.
  for (const auto& p : cloud.points) {
    const double shade = std::clamp(60.0 + 40.0 * (p.y + 1.5), 40.0, 200.0);
    const std::uint8_t c[3] = {static_cast<std::uint8_t>(shade), static_cast<std::uint8_t>(shade),
                               static_cast<std::uint8_t>(shade)};
    canvas.put(static_cast<int>(px(p.x)), static_cast<int>(py(p.z)), c);
  }
  const std::uint8_t brown[3] = {140, 80, 20};
  const std::uint8_t green[3] = {20, 170, 40};
  auto draw = [&](const evaluation::Polyline& p, const std::uint8_t c[3]) {
    for (std::size_t i = 0; i + 1 < p.points.size(); ++i) {
      const double r = std::max(1.0, 0.5 * p.diameters[i] * scale);
      canvas.line(px(p.points[i].x()), py(p.points[i].z()), px(p.points[i + 1].x()),
                  py(p.points[i + 1].z()), r, c);
    }
  };
  for (const auto& b : truth.primary_branches)
    draw(b, green);
  draw(truth.trunk, brown);
  if (!stbi_write_png(path.c_str(), canvas.w, canvas.h, 3, canvas.rgb.data(), canvas.w * 3)) {
    throw Error(ErrorCode::IO_FAILURE, "cannot write " + path);
  }
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
