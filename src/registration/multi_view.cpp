#include "dormant_tree_modeling/registration/multi_view.h"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <map>
#include <optional>
#include <sstream>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace registration {

namespace {

// A fit whose conditioning reaches this leaves no direction free in practice: full confidence.
constexpr double FULL_CONDITIONING = 0.05;

struct Station {
  int id = 0;
  std::vector<int> views;
  Pyramid pyramid;  // in the station frame
  std::optional<Eigen::Isometry3d> hint;
  Eigen::Isometry3d pose = Eigen::Isometry3d::Identity();  // station -> reference station
  bool placed = false, rejected = false;
  std::string reason;
  IcpResult fit;  // against the other stations
};

std::string metres(double m) {
  std::ostringstream s;
  s.precision(1);
  s << std::fixed << m * 1000 << " mm";
  return s.str();
}

// The union of the placed, accepted stations other than `skip`, in the reference frame.
Pyramid othersUnion(const std::vector<Station>& stations, std::size_t skip) {
  Pyramid u;
  for (std::size_t k = 0; k < stations.size(); ++k) {
    if (k != skip && stations[k].placed && !stations[k].rejected)
      append(u, transformed(stations[k].pyramid, stations[k].pose));
  }
  return u;
}

// Where the hints' world frame lies in the reference frame, from every placed station with a
// hint (each hint is off by its own error; their mean is off by less than any one).
std::optional<Eigen::Isometry3d> worldInReference(const std::vector<Station>& stations) {
  Eigen::Vector3d t = Eigen::Vector3d::Zero();
  double sin_sum = 0, cos_sum = 0;
  int n = 0;
  for (const auto& s : stations) {
    if (!s.placed || s.rejected || !s.hint)
      continue;
    // The platform stands upright: only the heading and the position are averaged.
    const Eigen::Isometry3d c = s.pose * s.hint->inverse();
    const double yaw = std::atan2(c.linear()(1, 0), c.linear()(0, 0));
    sin_sum += std::sin(yaw);
    cos_sum += std::cos(yaw);
    t += c.translation();
    ++n;
  }
  if (n == 0)
    return std::nullopt;
  Eigen::Isometry3d c = Eigen::Isometry3d::Identity();
  c.linear() = Eigen::AngleAxisd(std::atan2(sin_sum, cos_sum), Eigen::Vector3d::UnitZ()).matrix();
  c.translation() = t / n;
  return c;
}

// Why a fit is not good enough, or empty.
std::string judge(const IcpResult& fit, const RegistrationConfig& c) {
  if (fit.overlap < c.min_overlap)
    return "only " + std::to_string(static_cast<int>(fit.overlap * 100)) +
           " % of its points lie on the other views (needs " +
           std::to_string(static_cast<int>(c.min_overlap * 100)) + " %)";
  if (fit.rmse > c.max_rmse_m)
    return "fits the other views with rmse " + metres(fit.rmse) + " (limit " +
           metres(c.max_rmse_m) + ")";
  return "";
}

/// Stations in order of first appearance, each with its views' indices and the hint of its
/// first view.
std::vector<Station> groupStations(const std::vector<ViewInput>& views, bool use_hints) {
  std::vector<Station> stations;
  std::map<int, std::size_t> slot;
  for (std::size_t i = 0; i < views.size(); ++i) {
    const auto [it, fresh] = slot.emplace(views[i].station, stations.size());
    if (fresh) {
      stations.emplace_back();
      stations.back().id = views[i].station;
      if (use_hints)
        stations.back().hint = views[i].station_hint;
    }
    stations[it->second].views.push_back(static_cast<int>(i));
  }
  return stations;
}

/// A station's views merged in its own frame as an ICP pyramid (with the branch axes when
/// the ICP pairs them); too few points at the finest level leave the station out.
void prepareStation(Station& s, const std::vector<ViewInput>& views, const RegistrationConfig& c) {
  Points pts, dirs;
  std::vector<double> ranges;
  for (const int i : s.views) {
    const ViewInput& v = views[i];
    const Eigen::Vector3d sensor = v.in_station * v.sensor;
    for (const auto& p : v.points) {
      if (!p.allFinite())
        continue;
      const Eigen::Vector3d q = v.in_station * p;
      pts.push_back(q);
      const Eigen::Vector3d d = sensor - q;
      const double range = d.norm();
      ranges.push_back(range);
      dirs.push_back(range > 0 ? Eigen::Vector3d(d / range) : Eigen::Vector3d::Zero());
    }
  }
  s.pyramid = makePyramid(pts, dirs, c.icp.voxels_m, c.icp.normal_neighbors);
  if (c.icp.axis_pairs) {
    // One sample per source point of the finest ICP level (the level above the finest).
    const std::size_t centres = s.pyramid.levels.size() >= 2 ? s.pyramid.levels.size() - 2 : 0;
    s.pyramid.axes = estimateAxes(pts, dirs, ranges, s.pyramid.levels[centres].points, c.axes);
  }
  if (s.pyramid.levels.back().size() < c.min_points) {
    s.rejected = true;
    s.reason = "too few points (" + std::to_string(s.pyramid.levels.back().size()) +
               " at the finest level, needs " + std::to_string(c.min_points) + ")";
  }
}

/// The first station with enough points: the frame the others are placed in.
/// @throws Error EMPTY_INPUT when there is none
std::size_t chooseReference(std::vector<Station>& stations) {
  for (std::size_t k = 0; k < stations.size(); ++k) {
    if (!stations[k].rejected) {
      stations[k].placed = true;
      return k;
    }
  }
  throw Error(ErrorCode::EMPTY_INPUT,
              "registration: no view holds enough points (" + stations.front().reason + ")");
}

/// Why a station's placement is ambiguous (a second place, coarse.second_place_m or more from
/// the best, fits nearly as well), or nothing. Places are compared where they put the
/// station's centre: two headings alone move a pose's translation, not its points.
std::optional<std::string> ambiguity(const std::vector<IcpResult>& aligned, const IcpResult& best,
                                     const Eigen::Vector3d& centre, const RegistrationConfig& c) {
  for (const auto& r : aligned) {
    const double apart = (r.transform * centre - best.transform * centre).norm();
    if (apart >= c.coarse.second_place_m && r.overlap >= c.ambiguity_overlap_share * best.overlap) {
      std::ostringstream s;
      s.precision(2);
      s << std::fixed << "ambiguous: two places " << apart << " m apart fit alike (overlap "
        << best.overlap << " and " << r.overlap
        << "), as along a row of evenly spaced trees: register a crop around the tree";
      return s.str();
    }
  }
  return std::nullopt;
}

/// Places a station against everything placed so far: a coarse search (around its hint,
/// carried into the reference frame by the placed stations' hints), a few ICP levels on each
/// candidate, and the best by overlap refined on the rest; left out when a second place fits
/// nearly as well.
void placeStation(std::vector<Station>& stations, std::size_t k, const RegistrationConfig& c) {
  Station& s = stations[k];
  const Pyramid target = othersUnion(stations, k);
  std::optional<Eigen::Isometry3d> hint;
  if (s.hint) {
    if (const auto world = worldInReference(stations))
      hint = *world * *s.hint;
  }
  std::vector<CoarseCandidate> candidates;
  try {
    candidates =
        coarseSearch(s.pyramid.levels.front().points, target.levels.front().points, hint, c.coarse);
  } catch (const Error& e) {
    s.rejected = true;
    s.reason = std::string("coarse search failed: ") + e.what();
    return;
  }
  std::vector<IcpResult> aligned;
  for (const auto& cand : candidates) {
    try {
      aligned.push_back(
          alignPyramids(s.pyramid, target, cand.transform, c.icp, 0, c.candidate_levels - 1));
    } catch (const Error&) {
      // This candidate left the clouds apart; the others may not.
    }
  }
  if (aligned.empty()) {
    s.rejected = true;
    s.reason = "no candidate pose overlaps the views placed before it";
    return;
  }
  const auto best = std::max_element(
      aligned.begin(), aligned.end(),
      [](const IcpResult& a, const IcpResult& b) { return a.overlap < b.overlap; });
  if (const auto why = ambiguity(aligned, *best, centroid(s.pyramid.levels.front().points), c)) {
    s.rejected = true;
    s.reason = *why;
    return;
  }
  try {
    s.fit = alignPyramids(s.pyramid, target, best->transform, c.icp, c.candidate_levels);
    s.pose = s.fit.transform;
    s.placed = true;
  } catch (const Error& e) {
    s.rejected = true;
    s.reason = std::string("refinement failed: ") + e.what();
  }
}

/// One joint round: every placed station against all the others (Gauss-Seidel), on the
/// finest level only (placement left each near its place); then the stations that do not fit
/// leave the others' targets. The reference moves too (the frame is fixed afterwards): held
/// still, it would keep the others bent towards whatever error its first pairing left.
void refinementRound(std::vector<Station>& stations, std::size_t ref, const RegistrationConfig& c) {
  const int fine_first = static_cast<int>(c.icp.voxels_m.size()) - 1;
  for (std::size_t k = 0; k < stations.size(); ++k) {
    Station& s = stations[k];
    if (!s.placed || s.rejected)
      continue;
    const Pyramid target = othersUnion(stations, k);
    if (target.levels.empty()) {
      s.fit = IcpResult{};
      s.fit.overlap = 1.0;  // the only station: nothing to contradict it
      s.fit.conditioning = 1.0;
      continue;
    }
    try {
      const IcpResult r = alignPyramids(s.pyramid, target, s.pose, c.icp, fine_first);
      s.fit = r;
      if (c.refinement_rounds > 0)
        s.pose = r.transform;
    } catch (const Error& e) {
      s.fit = IcpResult{};
      s.fit.overlap = 0;
      s.reason = std::string("refinement failed: ") + e.what();
    }
  }
  for (std::size_t k = 0; k < stations.size(); ++k) {
    Station& s = stations[k];
    if (!s.placed || s.rejected || k == ref)
      continue;
    const std::string why = s.reason.empty() ? judge(s.fit, c) : s.reason;
    if (!why.empty()) {
      s.rejected = true;
      s.reason = why;
    }
  }
}

/// Each view's pose in the first registered view's frame, its station's fit, and why it was
/// left out.
RegistrationResult viewResults(const std::vector<ViewInput>& views,
                               const std::vector<Station>& stations, std::size_t ref) {
  RegistrationResult out;
  out.stations = static_cast<int>(stations.size());
  const Eigen::Isometry3d to_first = views[stations[ref].views.front()].in_station.inverse();
  out.views.resize(views.size());
  for (const auto& s : stations) {
    if (s.placed && !s.rejected)
      ++out.stations_registered;
    for (const int i : s.views) {
      ViewResult& v = out.views[i];
      v.name = views[i].name;
      v.station = s.id;
      v.registered = s.placed && !s.rejected;
      v.pose = to_first * s.pose * views[i].in_station;
      v.rmse = s.fit.rmse;
      v.overlap = s.fit.overlap;
      v.confidence = v.registered ? std::clamp(s.fit.overlap, 0.0, 1.0) *
                                        std::min(1.0, s.fit.conditioning / FULL_CONDITIONING)
                                  : 0.0;
      v.reason = v.registered ? "" : (s.reason.empty() ? "not placed" : s.reason);
    }
  }
  return out;
}

}  // namespace

RegistrationResult registerViews(const std::vector<ViewInput>& views, const RegistrationConfig& c) {
  c.validate();
  const auto t0 = std::chrono::steady_clock::now();
  const auto since = [&t0] {
    return std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  };
  if (views.empty())
    throw Error(ErrorCode::EMPTY_INPUT, "registration: no views");
  std::vector<Station> stations = groupStations(views, c.use_hints);
  for (auto& s : stations)
    prepareStation(s, views, c);
  const double t_prepared = since();
  const std::size_t ref = chooseReference(stations);
  for (std::size_t k = 0; k < stations.size(); ++k) {
    if (!stations[k].placed && !stations[k].rejected)
      placeStation(stations, k, c);
  }
  const double t_placed = since();
  for (int round = 0; round < std::max(1, c.refinement_rounds); ++round)
    refinementRound(stations, ref, c);
  // Back into the reference station's frame.
  const Eigen::Isometry3d gauge = stations[ref].pose.inverse();
  for (auto& s : stations)
    s.pose = gauge * s.pose;
  RegistrationResult out = viewResults(views, stations, ref);
  out.seconds = since();
  out.seconds_prepare = t_prepared;
  out.seconds_placement = t_placed - t_prepared;
  out.seconds_refinement = out.seconds - t_placed;
  return out;
}

Points mergeRegistered(const std::vector<ViewInput>& views, const RegistrationResult& result) {
  if (views.size() != result.views.size())
    throw Error(ErrorCode::INVALID_ARGUMENT, "registration result does not match the views");
  Points out;
  for (std::size_t i = 0; i < views.size(); ++i) {
    if (!result.views[i].registered)
      continue;
    for (const auto& p : views[i].points) {
      if (p.allFinite())
        out.push_back(result.views[i].pose * p);
    }
  }
  return out;
}

}  // namespace registration
}  // namespace dormant_tree_modeling
