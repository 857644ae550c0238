#pragma once

#include <cstdint>
#include <vector>

#include "dormant_tree_modeling/acquisition/stage_kinematics.h"
#include "dormant_tree_modeling/acquisition/view_plan.h"
#include "dormant_tree_modeling/modeling/modeler_config.h"
#include "dormant_tree_modeling/simulation/lms111_model.h"
#include "dormant_tree_modeling/simulation/scene.h"

namespace dormant_tree_modeling {
namespace simulation {

/// @brief How the trunk radius calibration is made: reference poles of known radii, standing
/// where the tree stands, scanned with the view plan at each range noise, measured by the
/// modeler's own trunk step (modeling::modelTrunk) with no calibration applied.
struct TrunkCalibrationOptions {
  std::vector<double> radii{0.005, 0.0075, 0.01, 0.015, 0.02, 0.03, 0.045, 0.07, 0.1};  ///< m
  std::vector<double> noise{0.003, 0.006, 0.012};  ///< range noise of the sensor, 1 sigma (m)
  double band_height = 0.35;                       ///< each radius is one band of the pole (m)
  double base_height = 0.3;                        ///< where the first band starts (m)
  Lms111Config sensor;
  acquisition::ViewPlanConfig plan;
  acquisition::StageGeometry geometry;
  modeling::ModelerConfig modeler;  ///< its trunk_calibration is ignored
  std::uint64_t seed = 1;
  int threads = 0;
};

/// @brief One measured band.
struct CalibrationSample {
  double radius = 0.0;          ///< true (m)
  double sensor_noise = 0.0;    ///< simulated range noise (m)
  double apparent = 0.0;        ///< median slice radius the modeler measured (m)
  double noise_estimate = 0.0;  ///< the modeler's noise estimate on the band (m)
};

/// @brief Result: the table and the samples behind it.
struct TrunkCalibrationResult {
  modeling::RadiusCalibration calibration;
  std::vector<CalibrationSample> samples;
};

/// @brief Every view of the plan through `scene` with range noise `noise`, merged into the
/// scene frame and cropped to `crop_radius` around the vertical axis through the origin.
std::vector<Eigen::Vector3d> scanReferenceScene(const Scene& scene, double noise,
                                                const TrunkCalibrationOptions& options,
                                                std::uint64_t seed, double crop_radius);

/// @brief @throws Error INVALID_ARGUMENT unless radii and noise are positive and ascending.
void checkCalibrationAxes(const TrunkCalibrationOptions& options);

/// @brief Append one noise level's row to a table: `bias[k]` where `measured[k]`, elsewhere
/// the nearest measured radius's bias; the noise axis value is kept ascending.
void appendCalibrationRow(modeling::RadiusCalibration& table, std::vector<double> bias,
                          const std::vector<char>& measured, double noise_axis);

/// @brief Scan two poles per noise level (radii ascending and descending, so that each radius
/// is seen both low and high) and tabulate apparent minus true radius. The table's noise axis
/// is the modeler's mean noise estimate at each level, since that is what it is looked up by.
/// @throws Error INVALID_ARGUMENT for empty or non-ascending radii or noise
TrunkCalibrationResult calibrateTrunkRadii(const TrunkCalibrationOptions& options);

}  // namespace simulation
}  // namespace dormant_tree_modeling
