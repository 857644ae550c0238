#include "dormant_tree_modeling/acquisition/sequencer.h"

#include <chrono>
#include <iomanip>
#include <regex>
#include <sstream>
#include <stdexcept>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace acquisition {

namespace {

double now() {
  return std::chrono::duration<double>(std::chrono::steady_clock::now().time_since_epoch()).count();
}

}  // namespace

std::vector<ViewOutcome> runPlan(const std::vector<PlannedView>& plan, const SequencerActions& a,
                                 int max_retries) {
  if (!a.move_platform || !a.move_slide || !a.acquire_view)
    throw Error(ErrorCode::INVALID_ARGUMENT, "the sequencer needs all three actions");
  if (max_retries < 0)
    throw Error(ErrorCode::INVALID_ARGUMENT, "max_retries must be >= 0");
  std::vector<ViewOutcome> outcomes;
  SequencerProgress p;
  p.total = static_cast<int>(plan.size());
  const double start = now();
  double view_time = 0.0;
  auto report = [&](const std::string& message) {
    p.message = message;
    p.elapsed_s = now() - start;
    const int finished = p.done + p.failed;
    p.remaining_s = finished > 0 ? view_time / finished * (p.total - finished) : 0.0;
    if (a.progress)
      a.progress(p);
  };
  int platform_index = -1;
  for (const auto& view : plan) {
    p.view = view.index + 1;
    if (a.cancelled && a.cancelled()) {
      report("cancelled");
      break;
    }
    if (view.platform_index != platform_index) {
      report("move the platform to position " + std::to_string(view.platform_index + 1) + " (" +
             view.side + ")");
      if (!a.move_platform(view)) {
        report("cancelled by the operator");
        break;
      }
      platform_index = view.platform_index;
    }
    ViewOutcome o;
    o.index = view.index;
    const double t0 = now();
    while (!o.ok && o.attempts <= max_retries) {
      ++o.attempts;
      report("view " + std::to_string(view.index + 1) + " of " + std::to_string(p.total) +
             (o.attempts > 1 ? ", attempt " + std::to_string(o.attempts) : ""));
      try {
        a.move_slide(view.slide);
        o.message = a.acquire_view(view);
        o.ok = true;
      } catch (const Error& e) {
        o.message = e.what();
      }
    }
    o.seconds = now() - t0;
    view_time += o.seconds;
    (o.ok ? p.done : p.failed) += 1;
    outcomes.push_back(o);
    report(o.ok ? "view " + std::to_string(view.index + 1) + " done"
                : "view " + std::to_string(view.index + 1) + " FAILED after " +
                      std::to_string(o.attempts) + " attempts: " + o.message);
  }
  return outcomes;
}

std::string outcomesMarkdown(const std::vector<ViewOutcome>& outcomes, int planned) {
  std::ostringstream out;
  int ok = 0;
  double seconds = 0;
  for (const auto& o : outcomes) {
    ok += o.ok ? 1 : 0;
    seconds += o.seconds;
  }
  out << ok << " of " << planned << " planned views acquired";
  if (static_cast<int>(outcomes.size()) < planned)
    out << " (run stopped after " << outcomes.size() << ")";
  out << ", " << seconds << " s of scanning.\n\n| view | result | attempts | s | details |\n"
      << "|---|---|---|---|---|\n";
  for (const auto& o : outcomes) {
    out << "| " << o.index + 1 << " | " << (o.ok ? "ok" : "FAILED") << " | " << o.attempts << " | "
        << o.seconds << " | " << o.message << " |\n";
  }
  return out.str();
}

std::string progressLine(const SequencerProgress& p) {
  std::ostringstream m;
  m << std::fixed << std::setprecision(1);
  m << p.done << " of " << p.total << " views done, " << p.failed << " failed, "
    << p.elapsed_s / 60.0 << " min elapsed, ";
  if (p.done + p.failed > 0)
    m << "about " << p.remaining_s / 60.0 << " min left: ";
  else
    m << "time left known after the first view: ";
  m << p.message;
  return m.str();
}

std::optional<int> viewsAcquired(const std::string& message) {
  static const std::regex FORM(R"(^finished: (\d+) of \d+ planned views acquired)");
  std::smatch m;
  if (!std::regex_search(message, m, FORM))
    return std::nullopt;
  try {
    return std::stoi(m[1].str());
  } catch (const std::out_of_range&) {
    return std::nullopt;
  }
}

}  // namespace acquisition
}  // namespace dormant_tree_modeling
