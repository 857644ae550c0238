#pragma once

#include <string>
#include <vector>

#include "dormant_tree_modeling/evaluation/ground_truth.h"
#include "dormant_tree_modeling/modeling/tree_model.h"

namespace dormant_tree_modeling {
namespace evaluation {

/// @brief The point of a polyline nearest to a query.
struct PolylinePoint {
  Eigen::Vector3d point = Eigen::Vector3d::Zero();
  double distance = 0.0;                                 ///< from the query, m
  double arc_length = 0.0;                               ///< from the polyline's start, m
  double diameter = 0.0;                                 ///< interpolated, m
  Eigen::Vector3d direction = Eigen::Vector3d::UnitZ();  ///< unit, of the segment holding it
};

/// @brief Nearest point of a polyline (at least two points) to q.
PolylinePoint closestPoint(const Polyline& line, const Eigen::Vector3d& q);

/// @brief Matching bounds of docs/evaluation.md.
struct MatchBounds {
  double min_distance = 0.03;   ///< e <= max(this, D(q))
  double max_arc_length = 1.0;  ///< s <= this
  double max_angle_deg = 30.0;  ///< axis vs polyline direction, sign ignored
};

/// @brief Whether a detection can match a polyline, and its e.
bool canMatch(const modeling::CylinderModel& detection, const Polyline& line,
              const MatchBounds& bounds, double* e = nullptr, PolylinePoint* at = nullptr);

/// @brief Minimum-cost one-to-one assignment (Hungarian algorithm) on a rows x cols matrix;
/// returns, per row, the assigned column or -1. Pairs with cost >= `forbidden` are never kept.
std::vector<int> assign(const std::vector<std::vector<double>>& cost, double forbidden);

/// @brief One matched branch.
struct BranchMatch {
  int detection = 0;  ///< index into model.primary_branches
  int truth = 0;      ///< index into truth.primary_branches
  double e = 0.0;
  double detected_diameter = 0.0;
  double true_diameter = 0.0;
};

/// @brief The evaluation row of docs/evaluation.md for one tree.
struct TreeScore {
  std::string name;
  int pb = 0;   ///< true primary branches
  int ipb = 0;  ///< detections, ignored ones excluded
  int tp = 0, fp = 0, fn = 0, ignored = 0;
  /// TP pairs whose detection's diameter was not measured (diameter_resolved false: at the
  /// floor, or a reading thinner radii give too); their errors count in the diameter columns
  /// as reported.
  int unresolved = 0;
  /// Of those, the ones whose true diameter lies in the range the model gave
  /// (diameter_min..diameter_max).
  int unresolved_in_range = 0;
  double fp_rate = 0.0, fn_rate = 0.0, f1 = 0.0;
  double branch_mae = 0.0, branch_rmse = 0.0, branch_bias = 0.0;  ///< m, over TP pairs
  double trunk_mae = 0.0;                                         ///< m, length-weighted
  double centerline_error = 0.0;                                  ///< m
  double coverage = 0.0;                                          ///< 0..1
  double runtime_s = 0.0;
  std::vector<BranchMatch> matches;
  std::vector<int> false_positives;     ///< indices into model.primary_branches
  std::vector<int> ignored_detections;  ///< near a minor branch only
  std::vector<int> missed;              ///< indices into truth.primary_branches (FN)
};

/// @brief Score a model against ground truth exactly as docs/evaluation.md defines.
TreeScore evaluate(const modeling::TreeModel& model, const GroundTruth& truth,
                   const MatchBounds& bounds = {});

/// @brief A Table-3-style text table: one row per tree and, for more than one, a mean row.
std::string formatTable(const std::vector<TreeScore>& scores);

/// @brief Per detection and per true branch, why it counted as it did: TP with its errors,
/// FP with the nearest true branch, ignored, FN with the nearest detection; and per trunk
/// cylinder its height, detected and true diameter. For finding what a model gets wrong.
std::string formatDetails(const TreeScore& score, const modeling::TreeModel& model,
                          const GroundTruth& truth);

/// @brief The scores as JSON (an object for one tree, with a "mean" for several).
std::string scoresToJson(const std::vector<TreeScore>& scores);

/// @brief Mean of every column.
TreeScore meanScore(const std::vector<TreeScore>& scores);

}  // namespace evaluation
}  // namespace dormant_tree_modeling
