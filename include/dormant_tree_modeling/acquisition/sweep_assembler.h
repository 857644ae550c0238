#pragma once

#include <cstddef>
#include <deque>
#include <optional>
#include <vector>

#include "dormant_tree_modeling/acquisition/range_image.h"

namespace dormant_tree_modeling {
namespace acquisition {

/// @brief One scan line as the LMS111 driver delivers it, ROS-free.
struct SweepLine {
  double stamp = 0.0;              ///< s, time of the first beam
  double time_increment = 0.0;     ///< s between beams
  double phi0 = 0.0;               ///< rad, device angle of beam 0 (0 down, pi/2 ahead)
  double phi_step = 0.0;           ///< rad between beams
  std::vector<float> ranges;       ///< m; 0 (or non-finite) = no return
  std::vector<float> intensities;  ///< optional, same length
};

/// @brief Stamped rotary-stage positions, to give each scan line the θ it was measured at,
/// whether the stage steps between lines or sweeps continuously under them.
class StagePositionHistory {
 public:
  /// @param max_gap_s interpolation between two samples further apart than this, or
  ///        extrapolation further than this past the ends, is refused
  /// @param capacity samples kept (oldest dropped)
  explicit StagePositionHistory(double max_gap_s = 0.1, std::size_t capacity = 100000)
      : max_gap_s_(max_gap_s), capacity_(capacity) {}
  /// @brief Add a sample; samples must come in time order (older ones are ignored).
  void add(double stamp, double theta);
  /// @brief θ at a time by linear interpolation, or nothing when the samples do not cover it.
  std::optional<double> at(double stamp) const;
  std::size_t size() const { return samples_.size(); }
  void clear() { samples_.clear(); }

 private:
  struct Sample {
    double stamp, theta;
  };
  double max_gap_s_;
  std::size_t capacity_;
  std::deque<Sample> samples_;
};

/// @brief The range image of one sweep: the lines whose θ (at their middle beam) lies in
/// [theta_min, theta_max), ordered by θ, each with its θ at beam 0 and its θ rate along the
/// beams. Lines without stage coverage are dropped and counted.
/// @param theta_step when > 0, one row per nominal θ_min + k·step (k < (max - min) / step):
///        the line nearest to it within half a step, or an empty row (counted in `missing`),
///        so that every view has the plan's row count whatever the phase of the laser
/// @throws Error INVALID_ARGUMENT when the lines disagree in beam count or angles
RangeImage assembleRangeImage(const std::vector<SweepLine>& lines,
                              const StagePositionHistory& history, double theta_min,
                              double theta_max, std::size_t* dropped = nullptr,
                              double theta_step = 0.0, std::size_t* missing = nullptr);

/// @brief Eq. 1's floating-pixel filter: remove pixel (i, j) when it differs from every one of
/// its 8 neighbours by more than rho_t (an invalid or missing neighbour counts as different).
/// The paper writes the signed difference; its stated purpose, isolated returns and mixed
/// returns at depth edges, needs the absolute one: a mixed pixel lies in front of the
/// background it blends with, so the signed minimum would keep it.
/// @returns pixels removed
std::size_t removeFloatingPixels(RangeImage& image, double rho_t);

/// @brief Range-noise smoothing on the image: each valid pixel becomes the mean of itself and
/// its valid 8-neighbours within rho_t (depth edges are not blurred across).
void smoothRanges(RangeImage& image, double rho_t, int iterations);

}  // namespace acquisition
}  // namespace dormant_tree_modeling
