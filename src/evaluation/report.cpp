#include <cstdio>
#include <nlohmann/json.hpp>

#include "dormant_tree_modeling/evaluation/matching.h"

namespace dormant_tree_modeling {
namespace evaluation {

namespace {

std::string row(const TreeScore& s) {
  char buf[256];
  std::snprintf(buf, sizeof(buf), "%-28s %4d %4d %7.2f%% %7.2f%% %7.2f%% %8.2f %8.2f %7.1f%% %8.2f",
                s.name.c_str(), s.pb, s.ipb, 100.0 * s.fp_rate, 100.0 * s.fn_rate, 100.0 * s.f1,
                1000.0 * s.branch_mae, 1000.0 * s.trunk_mae, 100.0 * s.coverage, s.runtime_s);
  return buf;
}

nlohmann::json toJson(const TreeScore& s) {
  return {{"name", s.name},
          {"pb", s.pb},
          {"ipb", s.ipb},
          {"tp", s.tp},
          {"fp", s.fp},
          {"fn", s.fn},
          {"ignored", s.ignored},
          {"unresolved_diameters", s.unresolved},
          {"unresolved_in_range", s.unresolved_in_range},
          {"fp_rate", s.fp_rate},
          {"fn_rate", s.fn_rate},
          {"f1", s.f1},
          {"branch_diameter_mae_mm", 1000.0 * s.branch_mae},
          {"branch_diameter_rmse_mm", 1000.0 * s.branch_rmse},
          {"branch_diameter_bias_mm", 1000.0 * s.branch_bias},
          {"trunk_diameter_mae_mm", 1000.0 * s.trunk_mae},
          {"centerline_error_mm", 1000.0 * s.centerline_error},
          {"coverage", s.coverage},
          {"runtime_s", s.runtime_s}};
}

}  // namespace

std::string formatTable(const std::vector<TreeScore>& scores) {
  std::string out =
      "tree                           PB  IPB  FP rate  FN rate       F1  br MAE mm  tr MAE mm  "
      "cover  runtime s\n";
  for (const auto& s : scores)
    out += row(s) + "\n";
  if (scores.size() > 1)
    out += row(meanScore(scores)) + "\n";
  return out;
}

std::string scoresToJson(const std::vector<TreeScore>& scores) {
  if (scores.size() == 1)
    return toJson(scores[0]).dump(2) + "\n";
  nlohmann::json trees = nlohmann::json::array();
  for (const auto& s : scores)
    trees.push_back(toJson(s));
  return nlohmann::json{{"trees", trees}, {"mean", toJson(meanScore(scores))}}.dump(2) + "\n";
}

}  // namespace evaluation
}  // namespace dormant_tree_modeling
