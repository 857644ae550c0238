#include <cmath>
#include <cstdio>
#include <string>

#include "dormant_tree_modeling/evaluation/matching.h"
#include "dormant_tree_modeling/modeling/geometry_fit.h"

namespace dormant_tree_modeling {
namespace evaluation {

namespace {

double polylineLength(const Polyline& line) {
  double length = 0.0;
  for (std::size_t k = 1; k < line.points.size(); ++k)
    length += (line.points[k] - line.points[k - 1]).norm();
  return length;
}

double axisAngleDeg(const Eigen::Vector3d& a, const Eigen::Vector3d& b) {
  return modeling::lineAngle(a.normalized(), b.normalized()) * 180.0 / M_PI;
}

/// The polyline (of a list) nearest to a point, its index and where on it.
int nearestPolyline(const std::vector<Polyline>& lines, const Eigen::Vector3d& q,
                    PolylinePoint* at) {
  int best = -1;
  for (std::size_t i = 0; i < lines.size(); ++i) {
    if (lines[i].points.size() < 2)
      continue;
    const PolylinePoint p = closestPoint(lines[i], q);
    if (best < 0 || p.distance < at->distance) {
      best = static_cast<int>(i);
      *at = p;
    }
  }
  return best;
}

}  // namespace

std::string formatDetails(const TreeScore& score, const modeling::TreeModel& model,
                          const GroundTruth& truth) {
  std::string out;
  char buf[320];
  auto line = [&](const char* text) { out += text; };
  std::snprintf(buf, sizeof(buf), "%s: TP %d, FP %d, FN %d, ignored %d\n", score.name.c_str(),
                score.tp, score.fp, score.fn, score.ignored);
  line(buf);
  for (const auto& m : score.matches) {
    const auto& c = model.primary_branches[m.detection].cylinder;
    const auto& measured = model.primary_branches[m.detection].measurement;
    char range[64] = "";
    if (!measured.diameter_resolved)
      std::snprintf(range, sizeof(range), "  not measured: %.1f to %.1f mm",
                    1000 * measured.diameter_min, 1000 * measured.diameter_max);
    std::snprintf(buf, sizeof(buf),
                  "  TP  det %3d z %5.2f m  d %5.1f mm | truth %3d d %5.1f mm  err %+5.1f mm  "
                  "e %4.1f mm%s\n",
                  c.id, c.center.z(), 1000 * m.detected_diameter,
                  truth.primary_branches[m.truth].id, 1000 * m.true_diameter,
                  1000 * (m.detected_diameter - m.true_diameter), 1000 * m.e, range);
    line(buf);
  }
  for (const int d : score.false_positives) {
    const auto& c = model.primary_branches[d].cylinder;
    PolylinePoint p, q;
    const int t = nearestPolyline(truth.primary_branches, c.center, &p);
    const int minor = nearestPolyline(truth.minor_branches, c.center, &q);
    std::snprintf(buf, sizeof(buf),
                  "  FP  det %3d z %5.2f m  d %5.1f mm | nearest truth %3d at %5.0f mm (s %4.2f m, "
                  "angle %3.0f deg, d %4.1f mm), nearest minor at %5.0f mm\n",
                  c.id, c.center.z(), 1000 * c.diameter, t >= 0 ? truth.primary_branches[t].id : -1,
                  t >= 0 ? 1000 * p.distance : -1.0, p.arc_length,
                  t >= 0 ? axisAngleDeg(c.axis, p.direction) : 0.0, 1000 * p.diameter,
                  minor >= 0 ? 1000 * q.distance : -1.0);
    line(buf);
  }
  for (const int d : score.ignored_detections) {
    const auto& c = model.primary_branches[d].cylinder;
    std::snprintf(buf, sizeof(buf), "  ign det %3d z %5.2f m  d %5.1f mm (a minor branch)\n", c.id,
                  c.center.z(), 1000 * c.diameter);
    line(buf);
  }
  for (const int t : score.missed) {
    const Polyline& b = truth.primary_branches[t];
    double nearest = -1.0;
    for (const auto& pb : model.primary_branches) {
      const double e = closestPoint(b, pb.cylinder.center).distance;
      if (nearest < 0.0 || e < nearest)
        nearest = e;
    }
    std::snprintf(buf, sizeof(buf),
                  "  FN  truth %3d z %5.2f m  d %5.1f mm  length %4.2f m | nearest detection at "
                  "%5.0f mm\n",
                  b.id, b.points.front().z(), 1000 * b.diameters.front(), polylineLength(b),
                  1000 * nearest);
    line(buf);
  }
  for (const auto& c : model.trunk) {
    const PolylinePoint q = closestPoint(truth.trunk, c.center);
    std::snprintf(buf, sizeof(buf),
                  "  trunk %2d z %5.2f m  length %4.2f m  d %5.1f mm | truth %5.1f mm  err %+5.1f "
                  "mm  off-axis %4.1f mm\n",
                  c.id, c.center.z(), c.length, 1000 * c.diameter, 1000 * q.diameter,
                  1000 * (c.diameter - q.diameter), 1000 * q.distance);
    line(buf);
  }
  return out;
}

}  // namespace evaluation
}  // namespace dormant_tree_modeling
