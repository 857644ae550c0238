#include "dormant_tree_modeling/registration/view_folder.h"

#include <pcl/point_cloud.h>
#include <pcl/point_types.h>
#include <algorithm>
#include <cmath>
#include <filesystem>
#include <iomanip>
#include <map>
#include <nlohmann/json.hpp>
#include <sstream>

#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/statistics.h"
#include "dormant_tree_modeling/io/point_cloud_io.h"
#include "dormant_tree_modeling/io/pose_json.h"
#include "dormant_tree_modeling/io/tree_json.h"

namespace dormant_tree_modeling {
namespace registration {

namespace {

// The ground's height in a view without a guess: the lowest 2 cm level holding 5 % of the
// points, or none.
std::optional<double> lowestDenseLevel(const Points& pts) {
  constexpr double BIN = 0.02;
  if (pts.empty())
    return std::nullopt;
  double lowest = INFINITY;
  for (const auto& p : pts)
    lowest = std::min(lowest, p.z());
  std::map<long, std::size_t> bins;
  for (const auto& p : pts)
    ++bins[static_cast<long>((p.z() - lowest) / BIN)];
  for (const auto& [bin, n] : bins) {
    if (n >= 0.05 * pts.size())
      return lowest + (bin + 1) * BIN;
  }
  return std::nullopt;
}

}  // namespace

ViewFolder readViewFolder(const std::string& dir, const ViewFolderConfig& options) {
  const std::string index_path = dir + "/views.json";
  if (!std::filesystem::exists(index_path))
    throw Error(ErrorCode::FILE_NOT_FOUND, index_path + " does not exist (not a folder of views)");
  ViewFolder f;
  try {
    const auto doc = nlohmann::json::parse(io::readTextFile(index_path));
    std::map<int, Eigen::Isometry3d> station_frame;  // first view's guess per station
    for (const auto& v : doc.at("views")) {
      ViewInput in;
      in.name = v.at("name").get<std::string>();
      in.station = v.value("platform_index", v.value("index", 0));
      // Keys read by other tools must hold what views.json documents, not any JSON value.
      for (const char* key : {"slide", "points"}) {
        if (v.contains(key) && !v.at(key).is_number())
          throw Error(ErrorCode::PARSE_ERROR, index_path + ": view " + in.name + ": '" + key +
                                                  "' must be a number, is " + v.at(key).dump());
      }
      const auto truth = io::poseFromJson(v, "true_pose");
      const auto guess = io::poseFromJson(v, "guess_pose");
      f.true_poses.push_back(truth);
      f.guess_poses.push_back(guess);
      if (guess) {
        const auto [it, fresh] = station_frame.emplace(in.station, *guess);
        in.in_station = it->second.inverse() * *guess;
        if (options.use_guesses)
          in.station_hint = it->second;
      }
      const bool guided = guess && options.use_guesses;
      const std::string cloud_path = dir + "/views/" + in.name + ".pcd";
      io::CloudReadConfig ro;
      ro.allow_empty = true;
      ro.recenter_threshold = INFINITY;
      const auto cloud = io::readCloud(cloud_path, ro).cloud;
      // The tree is where the guess expects it (the world origin); without a guess, at the
      // plan's standoff ahead, anywhere along the slide.
      const Eigen::Vector2d expected =
          guided ? Eigen::Vector2d(guess->inverse().translation().head<2>())
                 : Eigen::Vector2d(options.standoff, 0.0);
      for (const auto& p : cloud->points) {
        const Eigen::Vector3d q = p.getVector3fMap().cast<double>();
        const double off =
            guided ? (q.head<2>() - expected).norm() : std::abs(q.x() - expected.x());
        if (q.allFinite() && (options.crop_radius <= 0 || off <= options.crop_radius))
          in.points.push_back(q);
      }
      if (options.ground_margin >= 0) {
        const std::optional<double> ground =
            guided ? std::optional<double>(-guess->translation().z()) : lowestDenseLevel(in.points);
        if (ground) {
          const double floor = *ground + options.ground_margin;
          in.points.erase(
              std::remove_if(in.points.begin(), in.points.end(),
                             [floor](const Eigen::Vector3d& q) { return q.z() < floor; }),
              in.points.end());
        }
      }
      if (in.points.size() < FEW_VIEW_POINTS) {
        f.warnings.push_back("view " + in.name + " holds " + std::to_string(in.points.size()) +
                             " points (after the crop): it adds nothing to its station");
      }
      f.views.push_back(std::move(in));
    }
  } catch (const nlohmann::json::exception& e) {
    throw Error(ErrorCode::PARSE_ERROR, index_path + ": " + e.what());
  }
  return f;
}

namespace {

/// The errors of `got` against `truth`, view by view, both in one frame.
PoseErrorFigures poseErrorFigures(const std::vector<Eigen::Isometry3d>& truth,
                                  const std::vector<Eigen::Isometry3d>& got) {
  std::vector<double> dt, da;
  for (std::size_t i = 0; i < truth.size(); ++i) {
    const Eigen::Isometry3d d = truth[i].inverse() * got[i];
    dt.push_back((got[i].translation() - truth[i].translation()).norm() * 1000);
    da.push_back(Eigen::AngleAxisd(d.linear()).angle() * 180 / M_PI);
  }
  PoseErrorFigures e;
  e.median_mm = median(dt);
  e.median_deg = median(da);
  e.max_mm = *std::max_element(dt.begin(), dt.end());
  e.max_deg = *std::max_element(da.begin(), da.end());
  return e;
}

/// The rigid transform taking `got`'s frame onto `truth`'s that best fits each view's origin
/// and the 1 m tips of its axes (least squares, Umeyama without scale).
Eigen::Isometry3d bestAlignment(const std::vector<Eigen::Isometry3d>& truth,
                                const std::vector<Eigen::Isometry3d>& got) {
  constexpr int POINTS_PER_VIEW = 4;
  Eigen::Matrix3Xd from(3, POINTS_PER_VIEW * got.size()), to(3, POINTS_PER_VIEW * got.size());
  for (std::size_t i = 0; i < got.size(); ++i) {
    for (int k = 0; k < POINTS_PER_VIEW; ++k) {
      const Eigen::Vector3d local = k == 0 ? Eigen::Vector3d(Eigen::Vector3d::Zero())
                                           : Eigen::Vector3d(Eigen::Vector3d::Unit(k - 1));
      from.col(POINTS_PER_VIEW * i + k) = got[i] * local;
      to.col(POINTS_PER_VIEW * i + k) = truth[i] * local;
    }
  }
  return Eigen::Isometry3d(Eigen::umeyama(from, to, false));
}

}  // namespace

PoseErrors poseErrors(const RegistrationResult& result,
                      const std::vector<std::optional<Eigen::Isometry3d>>& true_poses) {
  PoseErrors e;
  std::vector<Eigen::Isometry3d> truth, got;
  for (std::size_t i = 0; i < result.views.size() && i < true_poses.size(); ++i) {
    if (result.views[i].registered && true_poses[i]) {
      truth.push_back(*true_poses[i]);
      got.push_back(result.views[i].pose);
    }
  }
  if (truth.empty())
    return e;
  e.views = static_cast<int>(truth.size());
  // The result's frame is the first registered view's: carried onto the truth by that view.
  const Eigen::Isometry3d first = truth.front() * got.front().inverse();
  std::vector<Eigen::Isometry3d> in_truth;
  for (const auto& g : got)
    in_truth.push_back(first * g);
  e.first_view = poseErrorFigures(truth, in_truth);
  const Eigen::Isometry3d best = bestAlignment(truth, got);
  for (std::size_t i = 0; i < got.size(); ++i)
    in_truth[i] = best * got[i];
  e.aligned = poseErrorFigures(truth, in_truth);
  return e;
}

std::string poseErrorText(const PoseErrorFigures& e) {
  std::ostringstream s;
  s << std::fixed << std::setprecision(1) << "median " << e.median_mm << " mm / "
    << std::setprecision(3) << e.median_deg << " deg, max " << std::setprecision(1) << e.max_mm
    << " mm / " << std::setprecision(3) << e.max_deg << " deg";
  return s.str();
}

const char* endName(RegistrationInput::End end) {
  switch (end) {
    case RegistrationInput::End::PLAN_FINISHED:
      return "plan_finished";
    case RegistrationInput::End::EXPECTED_VIEWS:
      return "expected_views";
    case RegistrationInput::End::INPUT_QUIET:
      return "input_quiet";
    case RegistrationInput::End::REQUEST:
      return "request";
  }
  return "request";
}

std::string registrationToJson(const RegistrationResult& r,
                               const std::optional<RegistrationInput>& input) {
  nlohmann::json views = nlohmann::json::array();
  for (const auto& v : r.views) {
    views.push_back({{"name", v.name},
                     {"station", v.station},
                     {"registered", v.registered},
                     {"pose", io::poseToJson(v.pose)},
                     {"rmse_m", v.rmse},
                     {"overlap", v.overlap},
                     {"confidence", v.confidence},
                     {"reason", v.reason}});
  }
  nlohmann::json out{{"format", "dormant_tree_registration/1"},
                     {"frame", "the first registered view's frame"},
                     {"stations", r.stations},
                     {"stations_registered", r.stations_registered},
                     {"seconds", r.seconds},
                     {"seconds_prepare", r.seconds_prepare},
                     {"seconds_placement", r.seconds_placement},
                     {"seconds_refinement", r.seconds_refinement},
                     {"views", views}};
  if (input) {
    out["input"] = {
        {"ended_by", endName(input->ended_by)},
        {"reported_views",
         input->reported_views ? nlohmann::json(*input->reported_views) : nlohmann::json(nullptr)},
        {"views_received", input->views_received},
        {"complete", input->complete()}};
  }
  return out.dump(1) + "\n";
}

std::string registrationReport(const RegistrationResult& r,
                               const std::optional<PoseErrors>& errors) {
  std::ostringstream s;
  s << std::fixed;
  int registered = 0;
  for (const auto& v : r.views)
    registered += v.registered;
  s << "# Registration\n\n"
    << registered << " of " << r.views.size() << " views registered (" << r.stations_registered
    << " of " << r.stations << " platform positions) in " << std::setprecision(1) << r.seconds
    << " s (preparation " << r.seconds_prepare << " s, placement " << r.seconds_placement
    << " s, joint refinement " << r.seconds_refinement
    << " s), into the frame of the first view.\n\n";
  if (errors && errors->views > 0) {
    s << "Against the true poses (" << errors->views
      << " views): " << poseErrorText(errors->first_view) << " in the first view's frame; "
      << poseErrorText(errors->aligned)
      << " with all poses aligned to the truth at once (the registered cloud's shape).\n\n";
  }
  s << "| view | station | registered | x m | y m | z m | yaw deg | rmse mm | overlap | "
       "confidence | note |\n|---|---|---|---|---|---|---|---|---|---|---|\n";
  for (const auto& v : r.views) {
    const Eigen::Vector3d t = v.pose.translation();
    const double yaw = std::atan2(v.pose.linear()(1, 0), v.pose.linear()(0, 0)) * 180 / M_PI;
    s << "| " << v.name << " | " << v.station << " | " << (v.registered ? "yes" : "**no**") << " | "
      << std::setprecision(3) << t.x() << " | " << t.y() << " | " << t.z() << " | "
      << std::setprecision(2) << yaw << " | " << std::setprecision(1) << v.rmse * 1000 << " | "
      << std::setprecision(2) << v.overlap << " | " << v.confidence << " | " << v.reason << " |\n";
  }
  return s.str();
}

Cloud registeredCloud(const std::vector<ViewInput>& views, const RegistrationResult& result) {
  Cloud merged;
  for (const auto& p : mergeRegistered(views, result))
    merged.push_back(pcl::PointXYZ(static_cast<float>(p.x()), static_cast<float>(p.y()),
                                   static_cast<float>(p.z())));
  return merged;
}

Cloud registeredFolderCloud(const std::string& dir, const ViewFolderConfig& options,
                            const ViewFolder& read, const RegistrationResult& result) {
  if (options.ground_margin < 0)
    return registeredCloud(read.views, result);
  ViewFolderConfig with_ground = options;
  with_ground.ground_margin = -1;
  return registeredCloud(readViewFolder(dir, with_ground).views, result);
}

void writeRegistration(const std::string& dir, const Cloud& registered,
                       const RegistrationResult& result, const std::optional<PoseErrors>& errors,
                       const std::optional<RegistrationInput>& input) {
  std::error_code ec;
  std::filesystem::create_directories(dir, ec);
  if (ec)
    throw Error(ErrorCode::IO_FAILURE, "cannot create " + dir + ": " + ec.message());
  io::writeCloud(dir + "/registered.pcd", registered);
  io::writeCloud(dir + "/registered.ply", registered);
  io::writeTextFile(dir + "/registration.json", registrationToJson(result, input));
  io::writeTextFile(dir + "/registration.md", registrationReport(result, errors));
}

}  // namespace registration
}  // namespace dormant_tree_modeling
