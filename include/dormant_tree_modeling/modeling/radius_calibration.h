#pragma once

#include <utility>
#include <vector>

namespace dormant_tree_modeling {
namespace modeling {

/// @brief Whether every value is larger than the one before (true for fewer than two).
bool strictlyAscending(const std::vector<double>& values);

/// @brief Where x lies on an ascending grid: the index of the grid point below it and the
/// fraction towards the next, clamped to the grid ({0, 0} for fewer than two points).
std::pair<std::size_t, double> gridPosition(const std::vector<double>& grid, double x);

/// @brief Piecewise-linear map of v from the ascending axis `from` onto `to` (same length, not
/// empty); below and above the ends in proportion to the end value (from's ends positive).
double mapAlong(const std::vector<double>& from, const std::vector<double>& to, double v);

/// @brief Systematic radius error of the trunk's slice estimate, apparent minus true, as a
/// table over the true radius and the range noise the modeler estimates. A laser beam that
/// partly hits a thin object reports its range along the beam centre, so each silhouette edge
/// gains returns up to a beam radius outside the surface (the footprint "wings"); the thinner
/// the object, the larger their share. Built by `calibrate_diameters` from reference cylinders
/// (simulated with the LMS111 model, or scanned in the field and measured with calipers).
struct RadiusCalibration {
  std::vector<double> radii;  ///< true radii, ascending (m)
  std::vector<double> noise;  ///< estimated range noise of each row, ascending (m)
  std::vector<double> bias;   ///< noise.size() rows of radii.size() values (m)

  /// @brief Whether the table is usable (non-empty, consistent sizes, ascending axes).
  bool valid() const;

  /// @brief Bias at a true radius and noise, bilinear; held constant beyond the radii and
  /// below the lowest noise, extrapolated along the two noisiest rows above the highest (up
  /// to one row spacing further), where the modeler's estimate of heavy noise on real trees
  /// runs past the reference scene's.
  double biasAt(double radius, double sigma) const;

  /// @brief The true radius whose apparent radius is `apparent` (inversion of
  /// apparent = r + bias(r, sigma)); `apparent` itself when the table is empty. Where several
  /// radii read alike (floorAmbiguity) it is one of them: resolves() says so.
  /// @param min_radius floor of the result (m)
  double correct(double apparent, double sigma, double min_radius) const;

  /// @brief Where the table cannot tell a radius from the floor at `sigma`: true radii up to
  /// `radius` each read (apparent = r + bias) no wider than some smaller radius down to the
  /// floor does, so apparent radii up to `apparent` have no single true radius (resolves() is
  /// false for them). Where the apparent radius grows everywhere above the floor that is the
  /// floor and its own apparent radius.
  struct FloorAmbiguity {
    double radius = 0.0;    ///< the largest true radius read as some smaller one (m)
    double apparent = 0.0;  ///< the widest apparent radius of the radii up to it (m)
  };

  /// @brief Whether `radius`, as correct() returned it, is a measurement: its apparent radius
  /// is wider than any the radii up to the floor's ambiguity read (false at the floor, and
  /// for a reading several radii give).
  /// @param radius a corrected radius (m)
  /// @param sigma the noise it was corrected at (m)
  /// @param floor_radius the smallest radius correct() returns (m)
  bool resolves(double radius, double sigma, double floor_radius) const;

  /// @brief The ambiguity at the floor (FloorAmbiguity), exact on the table's piecewise-linear
  /// apparent radius.
  /// @param floor_radius the smallest radius correct() returns (m)
  /// @param sigma the estimated range noise (m)
  FloorAmbiguity floorAmbiguity(double floor_radius, double sigma) const;
};

}  // namespace modeling
}  // namespace dormant_tree_modeling
