// The sweep watcher that finds rotary sweeps in recorded stage positions (rosbag replay).
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include "dormant_tree_modeling/acquisition/sweep_watcher.h"
#include "dormant_tree_modeling/common/error.h"
#include "dormant_tree_modeling/common/random.h"

using namespace dormant_tree_modeling;
using acquisition::SweepWatcher;
using acquisition::WatchedSweep;

namespace {

constexpr double DEG = M_PI / 180.0;

struct Sample {
  double t, theta;  // s, deg
};

// A stage trajectory at 50 Hz: piecewise-linear through (time, deg) knots.
std::vector<Sample> trajectory(const std::vector<Sample>& knots, double jitter_deg = 0.0) {
  std::vector<Sample> out;
  Rng rng(5);
  for (double t = knots.front().t; t <= knots.back().t + 1e-9; t += 0.02) {
    std::size_t k = 1;
    while (k + 1 < knots.size() && knots[k].t < t)
      ++k;
    const double a = (t - knots[k - 1].t) / (knots[k].t - knots[k - 1].t);
    const double theta =
        knots[k - 1].theta + std::clamp(a, 0.0, 1.0) * (knots[k].theta - knots[k - 1].theta);
    out.push_back({t, theta + jitter_deg * rng.normal()});
  }
  return out;
}

std::vector<WatchedSweep> watch(const std::vector<Sample>& samples) {
  SweepWatcher w(-45 * DEG, 45 * DEG);
  std::vector<WatchedSweep> found;
  for (const auto& s : samples) {
    if (auto sweep = w.add(s.t, s.theta * DEG))
      found.push_back(*sweep);
  }
  return found;
}

}  // namespace

TEST(SweepWatcher, FindsAlternatingContinuousSweeps) {
  // Home at 0, to the start, a rising sweep, a pause (slide move), a falling sweep, a pause.
  const auto found = watch(trajectory(
      {{0, 0}, {2, -45.5}, {3, -45.5}, {11, 45.5}, {14, 45.5}, {22, -45.5}, {24, -45.5}}, 0.002));
  ASSERT_EQ(found.size(), 2u);
  EXPECT_TRUE(found[0].upwards);
  // The run starts where the stage stood still at -45.5 (within one sample of t = 3 s) and
  // ends at the first position past 45 (t = 3 + 8 * 90.5 / 91 = 10.956 s).
  EXPECT_NEAR(found[0].begin, 3.0, 0.03);
  EXPECT_NEAR(found[0].end, 10.96, 0.03);
  EXPECT_FALSE(found[1].upwards);
  EXPECT_NEAR(found[1].begin, 14.0, 0.03);
  EXPECT_NEAR(found[1].end, 21.96, 0.03);
}

TEST(SweepWatcher, PausesDoNotEndARunAndPartialRunsAreNoSweeps) {
  // Step-and-scan-like pauses mid-run still make one sweep.
  const auto stepped = watch(trajectory({{0, -46}, {2, -10}, {3, -10}, {5, 46}}));
  ASSERT_EQ(stepped.size(), 1u);
  EXPECT_NEAR(stepped[0].begin, 0.0, 1e-9);
  // A run from 0 that reaches 45 did not start at the other end; a reversal at 40 is no sweep.
  EXPECT_TRUE(watch(trajectory({{0, 0}, {4, 46}})).empty());
  EXPECT_TRUE(watch(trajectory({{0, -46}, {4, 40}, {8, -46}})).empty());
  // The reversal at -46 starts a fresh run that does count.
  const auto back = watch(trajectory({{0, 46}, {4, -46}, {8, 46}}));
  ASSERT_EQ(back.size(), 2u);
  EXPECT_FALSE(back[0].upwards);
  EXPECT_TRUE(back[1].upwards);
  EXPECT_NEAR(back[1].begin, 4.0, 0.03);
}

TEST(SweepWatcher, IgnoresBadSamplesAndRejectsBadRanges) {
  SweepWatcher w(-45 * DEG, 45 * DEG);
  EXPECT_FALSE(w.add(0.0, -46 * DEG));
  EXPECT_FALSE(w.add(NAN, 0.0));
  EXPECT_FALSE(w.add(-1.0, 46 * DEG));  // older than the last sample
  EXPECT_FALSE(w.add(1.0, 0.0));
  ASSERT_TRUE(w.add(2.0, 46 * DEG));
  EXPECT_FALSE(w.add(2.1, 47 * DEG));  // reported once per run
  w.reset();
  EXPECT_FALSE(w.add(3.0, 47 * DEG));
  EXPECT_THROW(SweepWatcher(1.0, 1.0), Error);
  EXPECT_THROW(SweepWatcher(0.0, 1.0, 0.0), Error);
  EXPECT_THROW(SweepWatcher(0.0, 1.0, 2.0), Error);
}
