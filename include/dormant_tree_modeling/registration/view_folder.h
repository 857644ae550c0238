#pragma once

#include <Eigen/Geometry>
#include <optional>
#include <string>
#include <vector>

#include "dormant_tree_modeling/common/cloud.h"
#include "dormant_tree_modeling/registration/multi_view.h"

namespace dormant_tree_modeling {
namespace registration {

/// @brief How a folder of views is read.
struct ViewFolderConfig {
  /// Keep only points within this horizontal distance (m) of where the view's guess expects
  /// the tree (the simulation tool writes whole views; the rows beyond only cost time). The
  /// guess may be 0.5 m off, hence a wide crop; <= 0 keeps everything.
  double crop_radius = 1.2;
  /// m: without a guess the tree is this far ahead (+x) of the view's origin, somewhere
  /// along the slide; the crop then only bounds the distance ahead.
  double standoff = 1.5;
  /// Use the guessed platform poses for the crop, the ground and as registration hints (the
  /// slide moves within a station are used either way: they are exact).
  bool use_guesses = true;
  /// Drop points less than this (m) above the ground: the ground is a plane that any wrong
  /// heading still overlays, so it would hide bad fits from the overlap check. The ground lies
  /// the guess's height below the view's origin; without a guess, at the lowest 2 cm level
  /// holding 5 % of the points. < 0 keeps the ground.
  double ground_margin = 0.1;
};

/// @brief A folder of views: views.json (format dormant_tree_views/1, evaluation.md) and
/// views/<name>.pcd in each view's frame.
struct ViewFolder {
  std::vector<ViewInput> views;
  /// Per view, from views.json when present: the true pose and the guess (view -> world).
  std::vector<std::optional<Eigen::Isometry3d>> true_poses, guess_poses;
  /// What looked wrong but did not stop the reading (a view with almost no points).
  std::vector<std::string> warnings;
};

/// @brief A view with fewer points than this (after the crop) is worth a warning: it adds
/// nothing to its station and may be a file written by mistake.
constexpr std::size_t FEW_VIEW_POINTS = 100;

/// @brief Read a folder of views. Views sharing a platform_index form a station; their poses
/// within it come from the guesses (the slide moves are exact; only the platform is off).
/// @throws Error FILE_NOT_FOUND, PARSE_ERROR naming the file
ViewFolder readViewFolder(const std::string& dir, const ViewFolderConfig& options = {});

/// @brief How far registered views sit from their true poses: the median and largest
/// translation (mm) and rotation (deg) errors over the views.
struct PoseErrorFigures {
  double median_mm = 0, max_mm = 0, median_deg = 0, max_deg = 0;
};

/// @brief Pose errors of the registered views against the truth, read two ways.
struct PoseErrors {
  int views = 0;  ///< registered views with a true pose
  /// In the result's frame, the first registered view's: every view carries that view's own
  /// error as well as its own.
  PoseErrorFigures first_view;
  /// After the rigid transform that best aligns all registered poses with the true ones (a
  /// least-squares fit of each view's origin and its axes' 1 m tips): the registered cloud's
  /// own shape, whichever view's error the frame carries.
  PoseErrorFigures aligned;
};

/// @brief Compare registered poses with true ones (PoseErrors). Nothing (views 0) when no
/// registered view has a true pose.
PoseErrors poseErrors(const RegistrationResult& result,
                      const std::vector<std::optional<Eigen::Isometry3d>>& true_poses);

/// @brief The pose errors as one line of text: "median a mm / b deg, max c mm / d deg".
std::string poseErrorText(const PoseErrorFigures& e);

/// @brief How a registration's views came in, when a node collected them from a live or
/// replayed acquisition: what started the registration and whether every planned view was there.
struct RegistrationInput {
  /// What started the registration.
  enum class End {
    PLAN_FINISHED,   ///< the acquisition reported the plan's end
    EXPECTED_VIEWS,  ///< as many views arrived as the node was told to expect
    INPUT_QUIET,     ///< the recorded stage went silent before the plan's end (a bag that
                     ///< ended early, was cut off or lacks the end)
    REQUEST,         ///< a service call
  };
  End ended_by = End::REQUEST;
  /// views the acquisition reported acquired (its "finished" message), or expected_views
  std::optional<int> reported_views;
  int views_received = 0;
  /// @brief The plan reported its end (or the expected count came) and every view it named
  /// arrived.
  bool complete() const {
    return (ended_by == End::PLAN_FINISHED || ended_by == End::EXPECTED_VIEWS) && reported_views &&
           views_received >= *reported_views;
  }
};

/// @brief The name registration.json gives an end: "plan_finished", "expected_views",
/// "input_quiet" or "request".
const char* endName(RegistrationInput::End end);

/// @brief Per-view poses and figures as JSON (format dormant_tree_registration/1), with the
/// input's record under "input" when given.
std::string registrationToJson(const RegistrationResult& result,
                               const std::optional<RegistrationInput>& input = std::nullopt);

/// @brief A Markdown report: one row per view, the stations left out and why.
std::string registrationReport(const RegistrationResult& result,
                               const std::optional<PoseErrors>& errors);

/// @brief The registered views merged into one cloud (mergeRegistered as a PCL cloud).
Cloud registeredCloud(const std::vector<ViewInput>& views, const RegistrationResult& result);

/// @brief The registered cloud of the folder `dir`, registered as `read` with `options`: the
/// same views and crop at their registered poses, with the ground kept. The registration leaves
/// the ground out; a model needs the trunk's foot and the ground it stands on. The folder is
/// read again only when `options` left the ground out.
/// @throws Error as readViewFolder, INVALID_ARGUMENT when `result` is not of this folder
Cloud registeredFolderCloud(const std::string& dir, const ViewFolderConfig& options,
                            const ViewFolder& read, const RegistrationResult& result);

/// @brief Write a registration to a folder: registered.pcd and registered.ply (the merged
/// registered views, from registeredCloud), registration.json and registration.md. Creates
/// the folder.
/// @throws Error IO_FAILURE naming the file
void writeRegistration(const std::string& dir, const Cloud& registered,
                       const RegistrationResult& result,
                       const std::optional<PoseErrors>& errors = std::nullopt,
                       const std::optional<RegistrationInput>& input = std::nullopt);

}  // namespace registration
}  // namespace dormant_tree_modeling
