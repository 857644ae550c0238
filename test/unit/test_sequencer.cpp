// The acquisition sequencer's run logic: one operator move per platform position, a slide
// move and a sweep per view, retries, failures reported and the run going on, cancellation.
#include <gtest/gtest.h>

#include "dormant_tree_modeling/acquisition/sequencer.h"
#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace acquisition {
namespace {

std::vector<PlannedView> shortPlan() {
  ViewPlanConfig c;
  c.heights_m = {1.5};
  c.positions_per_height = 2;
  c.slide_steps = 3;
  c.back = false;
  return makeViewPlan(c);  // 2 positions x 3 views
}

TEST(Sequencer, RetriesReportsFailuresAndGoesOn) {
  const auto plan = shortPlan();
  ASSERT_EQ(plan.size(), 6u);
  std::vector<int> platform_moves;
  std::vector<double> slides;
  int sweeps = 0;
  std::vector<SequencerProgress> progress;
  SequencerActions a;
  a.move_platform = [&](const PlannedView& v) {
    platform_moves.push_back(v.platform_index);
    return true;
  };
  a.move_slide = [&](double s) { slides.push_back(s); };
  a.acquire_view = [&](const PlannedView& v) -> std::string {
    ++sweeps;
    if (v.index == 1 && sweeps == 2)
      throw Error(ErrorCode::IO_FAILURE, "laser dropped");  // once: the retry succeeds
    if (v.index == 4)
      throw Error(ErrorCode::IO_FAILURE, "axis X faulted");  // always: reported
    return "view " + std::to_string(v.index);
  };
  a.progress = [&](const SequencerProgress& p) { progress.push_back(p); };
  const auto out = runPlan(plan, a, 2);
  ASSERT_EQ(out.size(), 6u);
  EXPECT_EQ(platform_moves, (std::vector<int>{0, 1}));
  EXPECT_TRUE(out[1].ok);
  EXPECT_EQ(out[1].attempts, 2);
  EXPECT_FALSE(out[4].ok);
  EXPECT_EQ(out[4].attempts, 3);
  EXPECT_EQ(out[4].message, "axis X faulted");
  EXPECT_TRUE(out[5].ok);  // the run went on
  EXPECT_EQ(sweeps, 6 + 1 + 2);
  EXPECT_NEAR(slides[0], -0.1, 1e-12);  // centred on the slide
  EXPECT_EQ(progress.back().done, 5);
  EXPECT_EQ(progress.back().failed, 1);
  const std::string md = outcomesMarkdown(out, 6);
  EXPECT_EQ(md.rfind("5 of 6 planned views acquired", 0), 0u) << md;
  EXPECT_NE(md.find("| 5 | FAILED | 3 |"), std::string::npos) << md;
  // The plan's end message carries the count a replay's registration waits for.
  EXPECT_EQ(viewsAcquired("finished: " + md.substr(0, md.find('\n'))), 5);
}

TEST(Sequencer, ReadsTheViewCountOfAPlansEnd) {
  EXPECT_EQ(viewsAcquired("finished: 38 of 40 planned views acquired, 279.45 s of scanning."), 38);
  EXPECT_EQ(viewsAcquired("finished: 0 of 40 planned views acquired (run stopped after 3), 1 s"),
            0);
  EXPECT_FALSE(viewsAcquired("22 of 40 views done, 1 failed: view 23 done").has_value());
  EXPECT_FALSE(viewsAcquired("finished").has_value());
  EXPECT_FALSE(viewsAcquired("finished: 99999999999999 of 40 planned views acquired"));
}

TEST(Sequencer, ProgressLineGivesNoEstimateBeforeTheFirstViewAndMinutesToATenth) {
  SequencerProgress p;
  p.total = 40;
  p.elapsed_s = 7.2e-6;  // the first line of make demo once read "1.2e-07 min elapsed, about 0"
  p.message = "view 1: moving the slide";
  EXPECT_EQ(progressLine(p),
            "0 of 40 views done, 0 failed, 0.0 min elapsed, time left known after the first "
            "view: view 1: moving the slide");
  p.done = 3;
  p.failed = 1;
  p.elapsed_s = 93.0;
  p.remaining_s = 840.0;
  p.message = "view 5: sweeping";
  EXPECT_EQ(progressLine(p),
            "3 of 40 views done, 1 failed, 1.6 min elapsed, about 14.0 min left: view 5: sweeping");
}

TEST(Sequencer, StopsWhenTheOperatorOrTheUserCancels) {
  const auto plan = shortPlan();
  SequencerActions a;
  a.move_platform = [](const PlannedView& v) { return v.platform_index == 0; };
  a.move_slide = [](double) {};
  a.acquire_view = [](const PlannedView&) { return std::string("ok"); };
  EXPECT_EQ(runPlan(plan, a, 0).size(), 3u);  // the second position was refused
  int views = 0;
  a.move_platform = [](const PlannedView&) { return true; };
  a.acquire_view = [&](const PlannedView&) {
    ++views;
    return std::string("ok");
  };
  a.cancelled = [&] { return views >= 2; };
  const auto out = runPlan(plan, a, 0);
  EXPECT_EQ(out.size(), 2u);
  EXPECT_NE(outcomesMarkdown(out, 6).find("run stopped after 2"), std::string::npos);
  a.move_slide = nullptr;
  EXPECT_THROW(runPlan(plan, a, 0), Error);
}

}  // namespace
}  // namespace acquisition
}  // namespace dormant_tree_modeling
