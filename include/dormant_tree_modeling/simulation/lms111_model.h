#pragma once

#include <Eigen/Geometry>
#include <cstdint>
#include <string>
#include <vector>

#include "dormant_tree_modeling/common/random.h"
#include "dormant_tree_modeling/simulation/primitives.h"
#include "dormant_tree_modeling/simulation/ray_caster.h"

namespace dormant_tree_modeling {
namespace simulation {

/// @brief How the simulated SICK LMS111 samples and errs. Sources: SICK LMS1xx operating
/// instructions (8012471) and the datasheet values collected in docs/hardware.md.
struct Lms111Config {
  double angular_resolution_deg = 0.25;  ///< 0.25 (with 25 Hz) or 0.5 (with 50 Hz)
  double scan_frequency_hz = 25.0;       ///< 25 or 50
  double start_angle_deg = -45.0;        ///< device convention: 0 down, 90 ahead, 180 up
  double stop_angle_deg = 225.0;         ///< exclusive: 1080 beams at 0.25 deg (architecture.md)
  double min_range = 0.5;                ///< m, datasheet; nearer returns are reported invalid
  double max_range = 20.0;               ///< m, datasheet (10 % reflectance)
  double range_noise_sigma = 0.012;      ///< m, 1 sigma statistical error (datasheet +/-12 mm)
  /// Noise growing with range: sigma(d) = range_noise_sigma + this x d (m per m; 0: constant)
  double range_noise_per_m = 0.0;
  double range_bias = 0.0;  ///< m, systematic error of this unit (datasheet: typ. within +/-30 mm)
  double beam_exit_diameter = 0.008;  ///< m at the optics cover (operating instructions 3.6.2)
  double beam_divergence = 0.015;     ///< rad, full angle (operating instructions 3.6.2)
  int beam_samples = 7;               ///< rays across the beam footprint: 1 (ideal) or 7
  /// Returns along one beam closer than this merge into one echo whose range is their
  /// energy-weighted mean (the mixed pixels of Eq. 1); ~ the pulse length of a 3 ns pulse.
  double echo_merge_distance = 0.45;
  /// Echo energy, as a fraction of a full beam on a white (100 %) target at normal incidence,
  /// below which nothing is reported: a 2 mm wire at 1.5 m is at the edge of detection.
  double detection_threshold = 0.03;
  double grazing_dropout_start_deg = 75.0;  ///< incidence where dropouts begin
  double grazing_dropout_full_deg = 88.0;   ///< incidence where every return drops out

  /// @brief Beams per scan line.
  int beamCount() const;
  /// @brief Validate the values; @throws Error INVALID_ARGUMENT naming the bad field.
  void validate() const;
};

/// @brief A sensor whose physics differs from this model's (for worlds the modeler is only
/// scored on): "ours" (the defaults), "thin_beam" (one ray: no footprint widening),
/// "wide_beam" (12 mm exit, 25 mrad divergence), "far_noise" (noise growing 2 mm per metre
/// of range, echoes merging over 1.2 m: more mixed pixels). Range noise stays the default's: set it
/// after.
/// @throws Error INVALID_ARGUMENT naming the known variants
Lms111Config sensorVariant(const std::string& name);
/// @brief The names sensorVariant() knows.
std::vector<std::string> sensorVariantNames();

/// @brief One simulated scan line, as the device would report it.
struct ScanLine {
  std::vector<float> ranges;       ///< m; 0 = no valid return
  std::vector<std::uint8_t> rssi;  ///< 0..255 echo strength
  std::vector<Label> labels;       ///< true surface of the (dominant) echo
};

/// @brief Simulates scan lines of an LMS111 against a scene.
class Lms111Model {
 public:
  /// @param caster the scene; must outlive the model
  /// @param config sensor behaviour (validated)
  Lms111Model(const RayCaster& caster, const Lms111Config& config);

  /// @brief One scan line from a laser pose. The scan plane is the laser's x-z plane; beam phi
  /// points along (sin phi, 0, -cos phi) in the laser frame.
  /// @param laser_pose laser frame in the scene frame
  /// @param rng noise source (derive one per line for reproducible parallel runs)
  ScanLine scanLine(const Eigen::Isometry3d& laser_pose, Rng& rng) const;

  /// @brief Beam angle of column j, rad.
  double beamAngle(int j) const;

  const Lms111Config& config() const { return config_; }

 private:
  const RayCaster& caster_;
  Lms111Config config_;
  std::vector<Eigen::Vector2d> footprint_;  // unit-disc offsets of the beam samples
};

}  // namespace simulation
}  // namespace dormant_tree_modeling
