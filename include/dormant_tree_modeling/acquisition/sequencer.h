#pragma once

#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "dormant_tree_modeling/acquisition/view_plan.h"

namespace dormant_tree_modeling {
namespace acquisition {

/// @brief Where a run is, for the operator.
struct SequencerProgress {
  int view = 0;    ///< the view in hand (1-based); 0 before the first
  int done = 0;    ///< views acquired
  int failed = 0;  ///< views given up after their retries
  int total = 0;
  double elapsed_s = 0;
  double remaining_s = 0;  ///< estimate: mean time per view so far x views left
  std::string message;     ///< what happens now
};

/// @brief The operator's progress line: views done and failed, minutes elapsed to a tenth,
/// and the minutes left once a view has been timed (before, no estimate), then the message.
std::string progressLine(const SequencerProgress& progress);

/// @brief What became of one view.
struct ViewOutcome {
  int index = 0;
  bool ok = false;
  int attempts = 0;
  std::string message;  ///< the assembler's summary, or the last failure
  double seconds = 0;
};

/// @brief The steps of Algorithm 1 the sequencer drives; each throws Error on failure.
struct SequencerActions {
  /// Ask the operator to put the platform where the view needs it; false: the run is
  /// cancelled. Called once per platform position.
  std::function<bool(const PlannedView&)> move_platform;
  /// Move the slide to the view's position (m, the plan's: 0 at the slide's centre).
  std::function<void(double)> move_slide;
  /// Sweep and assemble one view; returns its summary.
  std::function<std::string(const PlannedView&)> acquire_view;
  std::function<void(const SequencerProgress&)> progress;  ///< optional
  std::function<bool()> cancelled;                         ///< optional
};

/// @brief Run a plan: per platform position one operator move, then per view a slide move
/// and a sweep, each view retried up to max_retries times; a view that still fails is
/// reported (never silently skipped) and the run goes on. Stops early when cancelled.
/// @throws Error INVALID_ARGUMENT when an action is missing or max_retries < 0
std::vector<ViewOutcome> runPlan(const std::vector<PlannedView>& plan,
                                 const SequencerActions& actions, int max_retries);

/// @brief The outcomes as a Markdown table with a summary line.
std::string outcomesMarkdown(const std::vector<ViewOutcome>& outcomes, int planned);

/// @brief How many views a plan's end message says were acquired.
/// @param message the acquisition's "finished: N of M planned views acquired, ..." (the
///        summary line of outcomesMarkdown after "finished: ")
/// @return N, or none when the message is not a plan's end in that form
std::optional<int> viewsAcquired(const std::string& message);

}  // namespace acquisition
}  // namespace dormant_tree_modeling
