#pragma once

#include <string>

#include "dormant_tree_modeling/modeling/modeler_config.h"
#include "dormant_tree_modeling/modeling/sensor_calibration.h"

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

}  // namespace test
}  // namespace dormant_tree_modeling
