// The scoring's one-to-one assignment against brute force, and its cost with thousands of
// detections.
#include <gtest/gtest.h>

#include <algorithm>
#include <functional>
#include <numeric>

#include "dormant_tree_modeling/common/random.h"
#include "dormant_tree_modeling/evaluation/matching.h"

namespace dormant_tree_modeling {
namespace evaluation {
namespace {

constexpr double FORBIDDEN = 1e9;

// (matches, total cost) of an assignment, matches first: what the scoring optimises.
std::pair<int, double> value(const std::vector<std::vector<double>>& cost,
                             const std::vector<int>& a) {
  int n = 0;
  double total = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i] >= 0) {
      ++n;
      total += cost[i][a[i]];
    }
  }
  return {n, total};
}

// Every injective partial assignment of rows to columns, the best by (matches, -cost).
std::pair<int, double> bruteForce(const std::vector<std::vector<double>>& cost) {
  const int rows = static_cast<int>(cost.size()), cols = static_cast<int>(cost[0].size());
  std::pair<int, double> best{0, 0.0};
  std::vector<int> a(rows, -1);
  std::vector<char> taken(cols, 0);
  std::function<void(int)> walk = [&](int i) {
    if (i == rows) {
      const auto v = value(cost, a);
      if (v.first > best.first || (v.first == best.first && v.second < best.second - 1e-12))
        best = v;
      return;
    }
    a[i] = -1;
    walk(i + 1);
    for (int j = 0; j < cols; ++j) {
      if (taken[j] || cost[i][j] >= FORBIDDEN)
        continue;
      taken[j] = 1;
      a[i] = j;
      walk(i + 1);
      taken[j] = 0;
      a[i] = -1;
    }
  };
  walk(0);
  return best;
}

TEST(Evaluate, CountsTheMatchedBranchesWhoseDiameterWasNotMeasured) {
  // Two branches leaving a 1 m trunk, each detected; the second detection's radius was
  // corrected to the floor. It still matches and its error counts as reported, and the score
  // says how many such pairs there are.
  GroundTruth truth;
  truth.trunk.points = {{0, 0, 0}, {0, 0, 1}};
  truth.trunk.diameters = {0.05, 0.04};
  modeling::TreeModel model;
  modeling::CylinderModel trunk;
  trunk.center = {0, 0, 0.5};
  trunk.diameter = 0.045;
  trunk.length = 1.0;
  model.trunk.push_back(trunk);
  for (int k = 0; k < 2; ++k) {
    const double z = 0.4 + 0.3 * k, sign = k == 0 ? 1.0 : -1.0;
    Polyline b;
    b.id = 10 + k;
    b.points = {{0, 0, z}, {sign * 0.5, 0, z}};
    b.diameters = {0.012, 0.012};
    truth.primary_branches.push_back(b);
    modeling::PrimaryBranch d;
    d.cylinder.id = k + 1;
    d.cylinder.center = {sign * 0.2, 0, z};
    d.cylinder.axis = {sign, 0, 0};
    d.cylinder.length = 0.3;
    d.cylinder.diameter = k == 0 ? 0.011 : 0.004;
    d.measurement.diameter_resolved = k == 0;
    d.measurement.diameter_min = k == 0 ? 0.011 : 0.004;
    d.measurement.diameter_max = k == 0 ? 0.011 : 0.0095;
    model.primary_branches.push_back(d);
  }
  const TreeScore s = evaluate(model, truth);
  EXPECT_EQ(s.tp, 2);
  EXPECT_EQ(s.unresolved, 1);
  EXPECT_EQ(s.unresolved_in_range, 0);  // 12 mm is wider than the 9.5 mm it may have
  EXPECT_NEAR(s.branch_mae, 0.5 * (0.001 + 0.008), 1e-12);
  const std::string details = formatDetails(s, model, truth);
  EXPECT_NE(details.find("not measured: 4.0 to 9.5 mm"), std::string::npos) << details;
  EXPECT_EQ(details.find("not measured"), details.rfind("not measured"));
  EXPECT_NE(details.find("d   4.0 mm | truth  11 d  12.0 mm  err  -8.0 mm  e"), std::string::npos)
      << details;
  EXPECT_NE(scoresToJson({s}).find("\"unresolved_diameters\": 1"), std::string::npos);
  EXPECT_EQ(meanScore({s, s}).unresolved, 2);
  model.primary_branches[1].measurement.diameter_max = 0.012;
  const TreeScore within = evaluate(model, truth);
  EXPECT_EQ(within.unresolved_in_range, 1);
  EXPECT_NE(scoresToJson({within}).find("\"unresolved_in_range\": 1"), std::string::npos);
  EXPECT_EQ(meanScore({s, within}).unresolved_in_range, 1);
}

TEST(Assign, FindsTheMostMatchesAtTheLeastCostLikeBruteForce) {
  Rng rng(11);
  for (int trial = 0; trial < 200; ++trial) {
    const int rows = 1 + trial % 6, cols = 1 + (trial / 6) % 6;
    std::vector<std::vector<double>> cost(rows, std::vector<double>(cols));
    for (auto& row : cost) {
      for (auto& c : row)
        c = rng.uniform() < 0.4 ? FORBIDDEN : std::round(rng.uniform(0.0, 10.0) * 8.0) / 8.0;
    }
    const auto a = assign(cost, FORBIDDEN);
    ASSERT_EQ(a.size(), cost.size());
    std::vector<int> used;
    for (const int j : a) {
      if (j >= 0)
        used.push_back(j);
    }
    std::sort(used.begin(), used.end());
    EXPECT_TRUE(std::adjacent_find(used.begin(), used.end()) == used.end()) << "one-to-one";
    const auto got = value(cost, a), best = bruteForce(cost);
    EXPECT_EQ(got.first, best.first) << "trial " << trial;
    EXPECT_NEAR(got.second, best.second, 1e-9) << "trial " << trial;
  }
}

TEST(Assign, ThousandsOfDetectionsAgainstDozensOfBranchesIsQuick) {
  // 5000 detections x 40 branches (O(n^3) on the padded square took minutes); each branch
  // has its own nearest detection at cost 0.
  const int detections = 5000, branches = 40;
  std::vector<std::vector<double>> cost(detections, std::vector<double>(branches, FORBIDDEN));
  for (int d = 0; d < detections; ++d) {
    const int t = d % branches;
    cost[d][t] = d < branches ? 0.0 : 1.0 + d * 1e-3;
  }
  const auto a = assign(cost, FORBIDDEN);
  for (int t = 0; t < branches; ++t)
    EXPECT_EQ(a[t], t);
  EXPECT_EQ(std::count(a.begin(), a.end(), -1), detections - branches);
}

}  // namespace
}  // namespace evaluation
}  // namespace dormant_tree_modeling
