#pragma once

#include <Eigen/Core>
#include <optional>
#include <vector>

#include "dormant_tree_modeling/modeling/trunk_model.h"

namespace dormant_tree_modeling {
namespace modeling {

/// @brief A trunk's taper: one smooth profile of its slices' corrected radii along the
/// centreline, r(t) = c0 + c1 sqrt(t) + c2 t + c3 t^2 with t the arc length scaled to [0, 1]
/// over the slices (a trunk thins fastest near the ground).
///
/// At 12 mm range noise a single slice's radius scatters by millimetres and the slices through
/// branch bases read centimetres wide; a segment's median slice carries both. The profile is
/// fitted to all slices at once, in rounds that leave out slices more than `below` robust
/// standard deviations under it or `above` over it (a branch base only widens a slice: the
/// upper bound may be the tighter one). The robust standard deviation (1.4826 x median
/// absolute residual) is the smaller of that over every slice and that over the slices under
/// the profile: wide slices inflate each in their own case (among steep scaffolds more than
/// half of the slices read wide; wide slices can lift the profile above every honest one).
///
/// The lowest slices are left out where they all read under the slices just above them: the
/// ground's mixed pixels pull a trunk base's circles in (a trunk thins upwards, so no honest
/// base slice reads thin). Below the lowest slice kept the profile holds its value there.
class TaperProfile {
 public:
  /// @brief The profile of the slices with a circle, or nothing when fewer than MIN_SLICES
  /// have one or the fit is degenerate.
  /// @param slices the trunk's slices, bottom up (Slice::corrected_radius is used)
  /// @param slice_height slice height (m): a slice is placed at its middle
  /// @param below robust standard deviations a slice may lie under the profile and stay in it
  /// @param above the same over it
  static std::optional<TaperProfile> fit(const std::vector<Slice>& slices, double slice_height,
                                         double below, double above);

  /// @brief Radius (m) at arc length s (held at the end values beyond the slices kept).
  double at(double s) const;

  /// @brief Mean radius (m) over arc lengths [a, b].
  double mean(double a, double b) const;

  static constexpr std::size_t MIN_SLICES = 8;  ///< slices with a circle a profile needs

 private:
  Eigen::Vector4d basis(double s) const;

  double s0_ = 0.0, s1_ = 1.0;
  double hold_ = 0.0;  ///< arc length of the lowest slice kept
  Eigen::Vector4d c_ = Eigen::Vector4d::Zero();
};

}  // namespace modeling
}  // namespace dormant_tree_modeling
