#pragma once

#include "dormant_tree_modeling/modeling/modeler_config.h"
#include "dormant_tree_modeling/modeling/radius_calibration.h"

namespace dormant_tree_modeling {
namespace modeling {

/// @brief The part of the trunk step's slice-radius bias (apparent minus true, m) that
/// Gaussian range noise alone causes, over true radius and noise: the very estimator
/// (measureSliceCircle with the config's band and iterations) run on ideal circles seen from
/// views all around, each return displaced along its beam. It depends on the estimator and the
/// noise, not on any scanner's footprint, so it holds for every scanner. Computed once per
/// process and configuration (about 0.2 s on 2 cores), seeded: equal configs, equal tables.
RadiusCalibration trunkNoiseBias(const ModelerConfig& config);

/// @brief The same for the branch step's raw radius (fitThinCylinder's trimmed RMS distance
/// from the axis) on ideal rods leaving at 0, 20 and 40 deg elevation, seen by level beams from
/// all around.
RadiusCalibration branchNoiseBias(const ModelerConfig& config);

/// @brief The noise estimate as the noise part's tables read it. The estimator
/// (estimateNoiseSigma) keeps the radial residuals within half a slice's radius: on a trunk
/// whose slices are not much thicker than the noise it reads less than on the 5 cm slices the
/// tables' noise axis stands for, and thin branches came out too thick (12 mm range noise, no
/// footprint, no calibration: +5.9 mm). Maps an estimate read on slices of `slice_radii` to
/// what 5 cm slices give for the same noise: with a calibration through its rig's readings
/// (SensorCalibration::standardReading), without one through the estimator's modelled readings,
/// which cover range noise only (a footprint's widening reads otherwise: thinner trunks read
/// more). TrunkModel::table_sigma.
/// @param sigma the estimate (m)
/// @param slice_radii radii standing for the slices it was read on (m); none leaves sigma
double standardNoiseReading(const ModelerConfig& config, double sigma,
                            const std::vector<double>& slice_radii);

/// @brief The table the stages apply: the noise part plus a footprint part (a calibration's
/// table, its noise axis clamped to its own rows: the footprint does not grow with noise), on
/// the noise part's grid. An empty footprint leaves the noise part.
RadiusCalibration addFootprint(const RadiusCalibration& noise_part,
                               const RadiusCalibration& footprint);

/// @brief Footprint bias at a radius and noise: the table's value with the noise clamped to
/// its rows (no extrapolation along the noise); 0 for an empty table.
double footprintBiasAt(const RadiusCalibration& footprint, double radius, double sigma);

}  // namespace modeling
}  // namespace dormant_tree_modeling
