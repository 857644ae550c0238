#include "dormant_tree_modeling/acquisition/sweep.h"

#include <cmath>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace acquisition {

void SweepConfig::validate() const {
  if (!(theta_min_deg < theta_max_deg && theta_step_deg > 0 && margin_deg >= 0 && settle_s >= 0)) {
    throw Error(ErrorCode::INVALID_ARGUMENT,
                "sweep: need theta_min_deg < theta_max_deg, theta_step_deg > 0, margin_deg >= 0, "
                "settle_s >= 0");
  }
}

RangeImage runSweep(const SweepIo& io, const SweepConfig& s, std::size_t* dropped,
                    std::size_t* missing) {
  s.validate();
  constexpr double DEG = M_PI / 180.0;
  const double period = io.scan_period();
  std::vector<SweepLine> lines;
  if (s.continuous) {
    const double here = io.rotary_position();
    const bool upwards = std::abs(here - s.theta_min_deg) <= std::abs(here - s.theta_max_deg);
    const double from = upwards ? s.theta_min_deg - s.margin_deg : s.theta_max_deg + s.margin_deg;
    const double to = upwards ? s.theta_max_deg + s.margin_deg : s.theta_min_deg - s.margin_deg;
    io.move_rotary(from, 0.0);
    const double t0 = io.now();
    io.move_rotary(to, s.theta_step_deg / period);
    lines = io.lines_between(t0, io.now());
  } else {
    const int steps =
        static_cast<int>(std::ceil((s.theta_max_deg - s.theta_min_deg) / s.theta_step_deg - 1e-9));
    for (int k = 0; k < steps; ++k) {
      io.move_rotary(s.theta_min_deg + k * s.theta_step_deg, 0.0);
      const auto line = io.first_line_after(io.now() + s.settle_s, 5 * period + 1.0);
      if (!line)
        throw Error(ErrorCode::IO_FAILURE, "no scan line at step " + std::to_string(k));
      lines.push_back(*line);
    }
  }
  if (lines.empty())
    throw Error(ErrorCode::EMPTY_INPUT, "no scan line arrived during the sweep");
  RangeImage image =
      assembleRangeImage(lines, io.history(), s.theta_min_deg * DEG, s.theta_max_deg * DEG, dropped,
                         s.theta_step_deg * DEG, missing);
  if (image.rows == 0) {
    throw Error(ErrorCode::EMPTY_INPUT, "no scan line of the sweep had stage positions (" +
                                            std::to_string(dropped ? *dropped : lines.size()) +
                                            " lines dropped)");
  }
  return image;
}

}  // namespace acquisition
}  // namespace dormant_tree_modeling
