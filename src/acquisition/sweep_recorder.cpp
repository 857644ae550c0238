#include "dormant_tree_modeling/acquisition/sweep_recorder.h"

#include <chrono>
#include <cmath>
#include <thread>

namespace dormant_tree_modeling {
namespace acquisition {

namespace {

// Stage feedback lags the scans by up to one feedback period (20 ms at 50 Hz): wait this long
// before reading the positions of a sweep that just ended.
constexpr auto FEEDBACK_SETTLE = std::chrono::milliseconds(50);
constexpr auto POLL = std::chrono::milliseconds(2);

}  // namespace

void SweepRecorder::addLine(SweepLine line, double scan_period) {
  std::lock_guard<std::mutex> lock(mutex_);
  period_ = scan_period;
  lines_.push_back(std::move(line));
  while (!lines_.empty() && lines_.back().stamp - lines_.front().stamp > buffer_s_)
    lines_.pop_front();
}

void SweepRecorder::addPosition(double stamp, double theta) {
  std::lock_guard<std::mutex> lock(mutex_);
  history_.add(stamp, theta);
  theta_ = theta;
}

std::vector<SweepLine> SweepRecorder::linesBetween(double t0, double t1) const {
  std::lock_guard<std::mutex> lock(mutex_);
  std::vector<SweepLine> out;
  for (const auto& l : lines_) {
    if (l.stamp >= t0 && l.stamp <= t1)
      out.push_back(l);
  }
  return out;
}

std::optional<SweepLine> SweepRecorder::firstLineAfter(double t, double timeout_s) const {
  const auto give_up = std::chrono::steady_clock::now() + std::chrono::duration<double>(timeout_s);
  while (std::chrono::steady_clock::now() < give_up) {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      for (const auto& l : lines_) {
        if (l.stamp > t)
          return l;
      }
    }
    std::this_thread::sleep_for(POLL);
  }
  return std::nullopt;
}

StagePositionHistory SweepRecorder::history() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return history_;
}

double SweepRecorder::rotaryPosition() const {
  std::lock_guard<std::mutex> lock(mutex_);
  return theta_;
}

std::optional<double> SweepRecorder::scanPeriod(double now, double max_age) const {
  std::lock_guard<std::mutex> lock(mutex_);
  if (period_ > 0 && !lines_.empty() && now - lines_.back().stamp < max_age)
    return period_;
  return std::nullopt;
}

void SweepRecorder::bind(SweepIo& io) const {
  io.rotary_position = [this] { return rotaryPosition() * 180.0 / M_PI; };
  io.lines_between = [this](double t0, double t1) { return linesBetween(t0, t1); };
  io.first_line_after = [this](double t, double timeout) { return firstLineAfter(t, timeout); };
  io.history = [this] {
    std::this_thread::sleep_for(FEEDBACK_SETTLE);
    return history();
  };
}

}  // namespace acquisition
}  // namespace dormant_tree_modeling
