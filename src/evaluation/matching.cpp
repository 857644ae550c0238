#include "dormant_tree_modeling/evaluation/matching.h"

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/modeling/geometry_fit.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace dormant_tree_modeling {
namespace evaluation {

PolylinePoint closestPoint(const Polyline& line, const Eigen::Vector3d& q) {
  PolylinePoint best;
  best.distance = std::numeric_limits<double>::infinity();
  double arc = 0.0;
  for (std::size_t i = 0; i + 1 < line.points.size(); ++i) {
    const Eigen::Vector3d a = line.points[i], ab = line.points[i + 1] - a;
    const double len = ab.norm();
    if (len <= 0.0)
      continue;
    const double t = std::clamp((q - a).dot(ab) / (len * len), 0.0, 1.0);
    const Eigen::Vector3d p = a + t * ab;
    const double d = (p - q).norm();
    if (d < best.distance) {
      best.distance = d;
      best.point = p;
      best.arc_length = arc + t * len;
      best.diameter = line.diameters[i] + t * (line.diameters[i + 1] - line.diameters[i]);
      best.direction = ab / len;
    }
    arc += len;
  }
  return best;
}

bool canMatch(const modeling::CylinderModel& detection, const Polyline& line,
              const MatchBounds& bounds, double* e, PolylinePoint* at) {
  const PolylinePoint q = closestPoint(line, detection.center);
  if (e)
    *e = q.distance;
  if (at)
    *at = q;
  const double angle = modeling::lineAngle(detection.axis.normalized(), q.direction);
  return q.distance <= std::max(bounds.min_distance, q.diameter) &&
         q.arc_length <= bounds.max_arc_length && angle <= bounds.max_angle_deg * M_PI / 180.0;
}

namespace {

// Kuhn-Munkres with potentials on an n x m matrix with n <= m: every row gets a distinct
// column, the total cost least. O(n^2 m), so the smaller side must be the rows.
std::vector<int> assignRows(const std::vector<std::vector<double>>& c, int n, int m) {
  const double inf = std::numeric_limits<double>::infinity();
  std::vector<double> u(n + 1, 0.0), v(m + 1, 0.0);
  std::vector<int> p(m + 1, 0), way(m + 1, 0);
  for (int i = 1; i <= n; ++i) {
    p[0] = i;
    int j0 = 0;
    std::vector<double> minv(m + 1, inf);
    std::vector<char> used(m + 1, 0);
    do {
      used[j0] = 1;
      const int i0 = p[j0];
      double delta = inf;
      int j1 = 0;
      for (int j = 1; j <= m; ++j) {
        if (used[j])
          continue;
        const double cur = c[i0 - 1][j - 1] - u[i0] - v[j];
        if (cur < minv[j]) {
          minv[j] = cur;
          way[j] = j0;
        }
        if (minv[j] < delta) {
          delta = minv[j];
          j1 = j;
        }
      }
      for (int j = 0; j <= m; ++j) {
        if (used[j]) {
          u[p[j]] += delta;
          v[j] -= delta;
        } else {
          minv[j] -= delta;
        }
      }
      j0 = j1;
    } while (p[j0] != 0);
    do {
      const int j1 = way[j0];
      p[j0] = p[j1];
      j0 = j1;
    } while (j0 != 0);
  }
  std::vector<int> row_to_col(n, -1);
  for (int j = 1; j <= m; ++j) {
    if (p[j] > 0)
      row_to_col[p[j] - 1] = j - 1;
  }
  return row_to_col;
}

}  // namespace

// Rows and columns without any allowed pair cannot be matched and are left out, and the
// smaller side becomes the rows: a model with thousands of detections against a tree's dozens
// of branches costs O(branches^2 x detections), not O(detections^3).
std::vector<int> assign(const std::vector<std::vector<double>>& cost, double forbidden) {
  const int rows = static_cast<int>(cost.size());
  const int cols = rows > 0 ? static_cast<int>(cost[0].size()) : 0;
  std::vector<int> result(rows, -1);
  std::vector<int> live_rows, live_cols;
  std::vector<char> col_live(cols, 0);
  for (int i = 0; i < rows; ++i) {
    bool any = false;
    for (int j = 0; j < cols; ++j) {
      if (cost[i][j] < forbidden) {
        any = true;
        col_live[j] = 1;
      }
    }
    if (any)
      live_rows.push_back(i);
  }
  for (int j = 0; j < cols; ++j) {
    if (col_live[j])
      live_cols.push_back(j);
  }
  if (live_rows.empty())
    return result;
  const bool transposed = live_rows.size() > live_cols.size();
  const std::vector<int>& a = transposed ? live_cols : live_rows;
  const std::vector<int>& b = transposed ? live_rows : live_cols;
  std::vector<std::vector<double>> c(a.size(), std::vector<double>(b.size()));
  for (std::size_t i = 0; i < a.size(); ++i) {
    for (std::size_t j = 0; j < b.size(); ++j) {
      const double v = transposed ? cost[b[j]][a[i]] : cost[a[i]][b[j]];
      c[i][j] = std::min(v, forbidden);
    }
  }
  const auto matched = assignRows(c, static_cast<int>(a.size()), static_cast<int>(b.size()));
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (matched[i] < 0)
      continue;
    const int r = transposed ? b[matched[i]] : a[i];
    const int col = transposed ? a[i] : b[matched[i]];
    if (cost[r][col] < forbidden)
      result[r] = col;
  }
  return result;
}

// More primary branches than any tree has (a model of noise): refused rather than scored.
constexpr std::size_t MAX_DETECTIONS = 100000;

namespace {

constexpr double FORBIDDEN = 1e9;  // the cost of a pair that cannot match
// Samples along each trunk cylinder for the centreline error: its ends and 3 between.
constexpr int CENTRE_SAMPLES = 4;

/// The cost of each detection-truth pair (its axis error), FORBIDDEN where they cannot
/// match; any_primary says which detections can match some primary branch.
std::vector<std::vector<double>> matchCosts(const modeling::TreeModel& model,
                                            const GroundTruth& truth, const MatchBounds& bounds,
                                            std::vector<char>& any_primary) {
  const int detections = static_cast<int>(model.primary_branches.size());
  const int pb = static_cast<int>(truth.primary_branches.size());
  std::vector<std::vector<double>> cost(detections, std::vector<double>(pb, FORBIDDEN));
  any_primary.assign(detections, 0);
  for (int d = 0; d < detections; ++d) {
    for (int t = 0; t < pb; ++t) {
      double e = 0.0;
      if (canMatch(model.primary_branches[d].cylinder, truth.primary_branches[t], bounds, &e)) {
        cost[d][t] = e;
        any_primary[d] = 1;
      }
    }
  }
  return cost;
}

/// The matched detections with their diameter errors; the unmatched ones are false positives,
/// or ignored when they match a minor branch and no primary.
void scoreDetections(const modeling::TreeModel& model, const GroundTruth& truth,
                     const MatchBounds& bounds, const std::vector<int>& assignment,
                     const std::vector<char>& any_primary, TreeScore& s, double& sq) {
  for (int d = 0; d < static_cast<int>(assignment.size()); ++d) {
    if (assignment[d] >= 0) {
      PolylinePoint at;
      double e = 0.0;
      canMatch(model.primary_branches[d].cylinder, truth.primary_branches[assignment[d]], bounds,
               &e, &at);
      BranchMatch m{d, assignment[d], e, model.primary_branches[d].cylinder.diameter, at.diameter};
      const double err = m.detected_diameter - m.true_diameter;
      s.branch_mae += std::abs(err);
      s.branch_bias += err;
      sq += err * err;
      const auto& measured = model.primary_branches[d].measurement;
      if (!measured.diameter_resolved) {
        ++s.unresolved;
        s.unresolved_in_range +=
            m.true_diameter >= measured.diameter_min && m.true_diameter <= measured.diameter_max;
      }
      s.matches.push_back(m);
      continue;
    }
    bool minor = false;
    if (!any_primary[d]) {
      for (const auto& m : truth.minor_branches)
        minor = minor || canMatch(model.primary_branches[d].cylinder, m, bounds);
    }
    if (minor) {
      ++s.ignored;
      s.ignored_detections.push_back(d);
    } else {
      ++s.fp;
      s.false_positives.push_back(d);
    }
  }
}

/// The counts, rates, F1 and mean diameter errors from the matches.
void summarise(TreeScore& s, int detections, double sq) {
  s.tp = static_cast<int>(s.matches.size());
  s.fn = s.pb - s.tp;
  std::vector<char> found(s.pb, 0);
  for (const auto& m : s.matches)
    found[m.truth] = 1;
  for (int t = 0; t < s.pb; ++t) {
    if (!found[t])
      s.missed.push_back(t);
  }
  s.ipb = detections - s.ignored;
  if (s.tp > 0) {
    s.branch_mae /= s.tp;
    s.branch_bias /= s.tp;
    s.branch_rmse = std::sqrt(sq / s.tp);
  }
  s.fp_rate = s.pb > 0 ? static_cast<double>(s.fp) / s.pb : 0.0;
  s.fn_rate = s.pb > 0 ? static_cast<double>(s.fn) / s.pb : 0.0;
  const int denom = 2 * s.tp + s.fp + s.fn;
  s.f1 = denom > 0 ? 2.0 * s.tp / denom : 1.0;
}

/// The trunk: diameter MAE weighted by cylinder length, the mean distance of the cylinders'
/// axes from the true centreline, and the share of the trunk up to its highest primary branch
/// that the cylinders cover.
void scoreTrunk(const modeling::TreeModel& model, const GroundTruth& truth, TreeScore& s) {
  double weight = 0.0, weighted = 0.0, centre_sum = 0.0;
  int centre_n = 0;
  std::vector<std::pair<double, double>> spans;
  for (const auto& c : model.trunk) {
    const PolylinePoint q = closestPoint(truth.trunk, c.center);
    weighted += c.length * std::abs(c.diameter - q.diameter);
    weight += c.length;
    for (int k = 0; k <= CENTRE_SAMPLES; ++k) {
      const Eigen::Vector3d p =
          c.center + (k / static_cast<double>(CENTRE_SAMPLES) - 0.5) * c.length * c.axis;
      centre_sum += closestPoint(truth.trunk, p).distance;
      ++centre_n;
    }
    const double a = closestPoint(truth.trunk, c.center - 0.5 * c.length * c.axis).arc_length;
    const double b = closestPoint(truth.trunk, c.center + 0.5 * c.length * c.axis).arc_length;
    spans.emplace_back(std::min(a, b), std::max(a, b));
  }
  s.trunk_mae = weight > 0.0 ? weighted / weight : 0.0;
  s.centerline_error = centre_n > 0 ? centre_sum / centre_n : 0.0;
  double top = 0.0;
  for (const auto& b : truth.primary_branches)
    top = std::max(top, closestPoint(truth.trunk, b.points.front()).arc_length);
  if (top <= 0.0)
    top = closestPoint(truth.trunk, truth.trunk.points.back()).arc_length;
  std::sort(spans.begin(), spans.end());
  double covered = 0.0, reach = 0.0;
  for (const auto& sp : spans) {
    const double a = std::max(sp.first, reach), b = std::min(sp.second, top);
    if (b > a)
      covered += b - a;
    reach = std::max(reach, sp.second);
  }
  s.coverage = top > 0.0 ? std::min(1.0, covered / top) : 0.0;
}

}  // namespace

TreeScore evaluate(const modeling::TreeModel& model, const GroundTruth& truth,
                   const MatchBounds& bounds) {
  TreeScore s;
  s.pb = static_cast<int>(truth.primary_branches.size());
  s.runtime_s = model.runtime_s;
  if (model.primary_branches.size() > MAX_DETECTIONS) {
    throw Error(ErrorCode::INVALID_ARGUMENT, "the model has " +
                                                 std::to_string(model.primary_branches.size()) +
                                                 " primary branches; no tree has more than " +
                                                 std::to_string(MAX_DETECTIONS) + ": not scored");
  }
  std::vector<char> any_primary;
  const auto cost = matchCosts(model, truth, bounds, any_primary);
  const auto assignment = assign(cost, FORBIDDEN);
  double sq = 0.0;
  scoreDetections(model, truth, bounds, assignment, any_primary, s, sq);
  summarise(s, static_cast<int>(model.primary_branches.size()), sq);
  scoreTrunk(model, truth, s);
  return s;
}

TreeScore meanScore(const std::vector<TreeScore>& scores) {
  TreeScore m;
  m.name = "mean";
  if (scores.empty())
    return m;
  const double n = static_cast<double>(scores.size());
  double pb = 0, ipb = 0;
  for (const auto& s : scores) {
    pb += s.pb;
    ipb += s.ipb;
    m.tp += s.tp;
    m.fp += s.fp;
    m.fn += s.fn;
    m.unresolved += s.unresolved;
    m.unresolved_in_range += s.unresolved_in_range;
    m.fp_rate += s.fp_rate / n;
    m.fn_rate += s.fn_rate / n;
    m.f1 += s.f1 / n;
    m.branch_mae += s.branch_mae / n;
    m.branch_rmse += s.branch_rmse / n;
    m.branch_bias += s.branch_bias / n;
    m.trunk_mae += s.trunk_mae / n;
    m.centerline_error += s.centerline_error / n;
    m.coverage += s.coverage / n;
    m.runtime_s += s.runtime_s / n;
  }
  m.pb = static_cast<int>(std::lround(pb / n));
  m.ipb = static_cast<int>(std::lround(ipb / n));
  return m;
}

}  // namespace evaluation
}  // namespace dormant_tree_modeling
