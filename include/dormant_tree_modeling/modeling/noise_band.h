#pragma once

namespace dormant_tree_modeling {
namespace modeling {

/// @brief Returns within this many sigmas of the range noise of a surface are on it: the one
/// band every circle, cylinder and region test of the modeler uses (2.5 sigma holds 98.8 % of
/// Gaussian noise, so a fit's inliers are nearly all its surface's returns).
constexpr double NOISE_BAND_SIGMAS = 2.5;

/// @brief The half-width (m) of the band around a surface that holds its returns at range
/// noise `sigma` (m).
constexpr double noiseBand(double sigma) {
  return NOISE_BAND_SIGMAS * sigma;
}

/// @brief The range noise (m) a band's half-width (m) stands for: noiseBand's inverse.
constexpr double sigmaOfBand(double band) {
  return band / NOISE_BAND_SIGMAS;
}

}  // namespace modeling
}  // namespace dormant_tree_modeling
