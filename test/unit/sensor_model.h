#pragma once

#include <string>

#include "dormant_tree_modeling/modeling/modeler_config.h"
#include "dormant_tree_modeling/modeling/sensor_calibration.h"
#include "dormant_tree_modeling/registration/multi_view.h"

namespace dormant_tree_modeling {
namespace test {

/// @brief The modeler's defaults with the calibration of our LMS111 sensor model
/// (config/calibration/lms111_model.yaml): what the virtual platform and the benches use on
/// scans of the simulator.
inline modeling::ModelerConfig sensorModelConfig() {
  modeling::ModelerConfig c;
  c.calibration = modeling::loadSensorCalibration(std::string(DTM_CONFIG_DIR) +
                                                  "/calibration/lms111_model.yaml");
  return c;
}

/// @brief The registration's defaults with the silhouette growth of that calibration.
inline registration::RegistrationConfig sensorModelRegistrationConfig() {
  registration::RegistrationConfig c;
  registration::applySensorCalibration(sensorModelConfig().calibration, c);
  return c;
}

}  // namespace test
}  // namespace dormant_tree_modeling
