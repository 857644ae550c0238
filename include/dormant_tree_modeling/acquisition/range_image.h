#pragma once

#include <cstdint>
#include <optional>
#include <vector>

#include "dormant_tree_modeling/common/cloud.h"

namespace dormant_tree_modeling {
namespace acquisition {

/// @brief One view as a range image rho(theta, phi): a row per scan line (rotary angle theta),
/// a column per beam (scan angle phi; 0 deg straight down, 90 deg horizontal towards the tree,
/// 180 deg straight up). A range of 0 means no valid return, as the device reports it.
struct RangeImage {
  int rows = 0;                    ///< scan lines (theta), e.g. 200
  int cols = 0;                    ///< beams per line (phi), e.g. 1080
  double theta0 = 0.0;             ///< rad, angle of row 0
  double theta_step = 0.0;         ///< rad between rows
  double phi0 = 0.0;               ///< rad, angle of column 0
  double phi_step = 0.0;           ///< rad between columns
  std::vector<float> range;        ///< m, row-major, 0 = invalid
  std::vector<std::uint8_t> rssi;  ///< optional, same layout (empty when unknown)
  std::vector<double> row_theta;  ///< optional measured theta per row (rad); empty: theta0 + i*step
  /// Optional, per row: how theta changes along the row (rad per column), for a stage that
  /// turns while the line is measured (a continuous sweep). Empty: constant along a row.
  std::vector<double> row_theta_rate;
  std::vector<double> row_stamp;  ///< optional: time of each row's first beam (s)

  /// @brief Allocate rows x cols invalid pixels.
  void resize(int r, int c);
  float& at(int row, int col) { return range[static_cast<std::size_t>(row) * cols + col]; }
  float at(int row, int col) const { return range[static_cast<std::size_t>(row) * cols + col]; }
  /// @brief Theta of a row (at column 0): the measured one when known.
  double theta(int row) const;
  /// @brief Theta of one pixel: the row's, moved on by the row's rate when known.
  double theta(int row, int col) const;
  /// @brief Phi of a column.
  double phi(int col) const { return phi0 + col * phi_step; }
  /// @brief Number of valid pixels.
  std::size_t validCount() const;
  /// @brief The image's time: the middle row's stamp, or that of the row nearest the middle
  /// that has a scan line (rows without one have stamp 0). None without row stamps.
  std::optional<double> middleStamp() const;
};

/// @brief Rotary-stage frame coordinates of a return (architecture.md):
/// x = rho sin(phi) cos(theta), y = rho sin(phi) sin(theta), z = -rho cos(phi).
void sphericalToCartesian(double rho, double theta, double phi, double& x, double& y, double& z);

/// @brief Every valid pixel as a point in the rotary-stage frame.
/// @param image range image
/// @param phi_min, phi_max keep only columns with phi in [phi_min, phi_max) (rad); the tree
///        lies in [0, pi), the rest of the 270 deg field looks behind the sensor
CloudPtr toCloud(const RangeImage& image, double phi_min = -1e9, double phi_max = 1e9);

}  // namespace acquisition
}  // namespace dormant_tree_modeling
