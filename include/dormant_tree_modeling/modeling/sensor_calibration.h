#pragma once

#include <string>
#include <vector>

#include "dormant_tree_modeling/modeling/radius_calibration.h"

namespace dormant_tree_modeling {
namespace modeling {

/// @brief What a calibration was measured on: the true radii of the rig's pipe sections and
/// rods, and the noise the modeler estimated on its scans (m). Outside it a table is held
/// constant, which the modeler reports.
struct CalibrationCoverage {
  double trunk_radius_min_m = 0.0, trunk_radius_max_m = 0.0;
  double branch_radius_min_m = 0.0, branch_radius_max_m = 0.0;
  double noise_min_m = 0.0, noise_max_m = 0.0;
};

/// @brief How far beyond the radii a calibration covers (a share of them) it is still used as
/// measured: about a rod's or a section's neighbourhood. Beyond, the modeler warns that its
/// tables were held constant, and the registration drops branch-axis samples.
constexpr double COVERAGE_RADIUS_SLACK = 0.15;

/// @brief The range of a silhouette's diameter gain (SensorCalibration::Silhouette). Below
/// the minimum a width tells diameters apart too little: a radius read from it would carry
/// more than 5 times the width's noise.
constexpr double MIN_DIAMETER_GAIN = 0.2;
constexpr double MAX_DIAMETER_GAIN = 1.5;

/// @brief Whether a diameter gain lies in [MIN_DIAMETER_GAIN, MAX_DIAMETER_GAIN] (false for NaN).
constexpr bool validDiameterGain(double gain) {
  return gain >= MIN_DIAMETER_GAIN && gain <= MAX_DIAMETER_GAIN;
}

/// @brief "[min, max]" of the diameter gain, for messages.
std::string diameterGainRange();

/// @brief The radius of the slices whose noise reading is the standard one (m): the noise axis
/// of every radius table (the noise part's and a calibration's) is what the modeler's noise
/// estimate reads on slices of this radius.
constexpr double STANDARD_READING_RADIUS_M = 0.05;

/// @brief What the modeler's noise estimate read on each pipe section of one rig scan, over
/// the sections' true radii: how one scanner's reading of the same noise varies with the
/// trunk's radius (a footprint reads more on thin sections, range noise alone less).
struct NoiseReading {
  std::vector<double> radii_m;  ///< the sections' true radii, ascending
  std::vector<double> noise_m;  ///< the estimate on each (m)

  /// @brief The reading at a radius: linear between sections, held beyond them; 0 when empty.
  double at(double radius) const;
};

/// @brief The part of one scanner's radius bias that range noise does not explain: the beam
/// footprint's widening of thin objects (apparent minus true radius, m, over the true radius
/// and the estimated noise, after the noise part of noise_bias.h is taken off). Made by
/// `calibrate_diameters` from scans of a rig of known diameters; loaded by
/// `tree_model --calibration` and the tree_modeler node's `~calibration_file`.
struct SensorCalibration {
  std::string name;  ///< empty: no calibration (the noise part alone is corrected)
  std::string hash;  ///< FNV-1a 64 of the file's bytes, 16 hex digits: which file it was
  RadiusCalibration trunk_footprint;   ///< of the trunk step's slice radius
  RadiusCalibration branch_footprint;  ///< of the branch step's raw radius
  CalibrationCoverage coverage;
  /// How wide a thin branch's one-sided silhouette looks, for the registration's branch axes:
  /// diameter_gain x diameter + growth_m + growth_per_m x range (m). Measured when the rig was
  /// given as views (calibrate_diameters --scan DIR); absent otherwise.
  struct Silhouette {
    bool measured = false;
    double growth_m = 0.0, growth_per_m = 0.0;
    double range_min_m = 0.0, range_max_m = 0.0;  ///< the ranges the rig's rods were seen at
    /// The share of the growth the registration takes off a silhouette so that its axes lie
    /// at the rods' depth (the footprint's wings carry the near surface's range).
    double depth_share = 1.0;
    /// How much of a diameter change the silhouette's width shows: 1 where the footprint only
    /// adds a margin; well below 1 where a wide beam's footprint makes thin and thick branches
    /// look alike (a radius read from the width then divides by it).
    double diameter_gain = 1.0;
  } silhouette;
  /// One per rig scan; the tables' noise axis is their readings at STANDARD_READING_RADIUS_M.
  /// Empty in files made before they were recorded: their rows hold the whole rig's estimate.
  std::vector<NoiseReading> noise_readings;
  std::vector<std::string> sources;  ///< the scans it was made from, for the record

  /// @brief Whether a calibration is set.
  bool given() const { return !name.empty(); }
  /// @brief An estimate read on slices of `slice_radii` mapped to what this scanner's
  /// STANDARD_READING_RADIUS_M sections read for the same noise, through the rig scans'
  /// readings (between scans linear, beyond them in proportion); sigma itself without
  /// readings or radii.
  double standardReading(double sigma, const std::vector<double>& slice_radii) const;
};

/// @brief FNV-1a 64 of bytes, as 16 lower-case hex digits.
std::string fnv1aHex(const std::string& bytes);

/// @brief Read a calibration file (YAML, top-level key `sensor_calibration`).
/// @throws Error FILE_NOT_FOUND, PARSE_ERROR (malformed YAML, a missing or unknown key, a value
///         of the wrong type), INVALID_ARGUMENT (tables not ascending, sizes that disagree,
///         a bias beyond +/-50 mm), each naming the file and the key
SensorCalibration loadSensorCalibration(const std::string& path);

/// @brief The file text of a calibration (what loadSensorCalibration reads back), with
/// `comment` (lines) at the top. The hash is not part of the text.
std::string sensorCalibrationToYaml(const SensorCalibration& calibration,
                                    const std::string& comment);

}  // namespace modeling
}  // namespace dormant_tree_modeling
