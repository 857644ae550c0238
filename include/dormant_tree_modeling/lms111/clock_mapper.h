#pragma once

#include <cstdint>
#include <deque>
#include <optional>

namespace dormant_tree_modeling {
namespace lms111 {

/// @brief Maps the device's µs clock (32 bit, wrapping every 71.6 min) to host time, so that
/// scans are stamped when their first ray was measured, without the jitter of the network and
/// the host, and following the drift between the two oscillators.
///
/// Each telegram gives a pair (device time of transmission, host time of reception). The
/// reception lags the transmission by a delay that is never negative, so over a window of
/// pairs the host-minus-device offset's lower envelope is the clock offset plus the smallest
/// delay; the drift is the least-squares slope of host against device time over the window.
class ClockMapper {
 public:
  /// @param window_s how much history the fit uses, s of device time
  /// @param max_drift_ppm a fitted drift beyond this is clamped (crystals: tens of ppm)
  explicit ClockMapper(double window_s = 30.0, double max_drift_ppm = 500.0)
      : window_s_(window_s), max_drift_(max_drift_ppm * 1e-6) {}

  /// @brief Add one observation. A device clock that goes backwards (a reboot) restarts the
  /// mapping. @returns whether the mapping was restarted
  bool observe(std::uint32_t device_us, double host_s);

  /// @brief Host time of a device time near the observed ones (wrap handled); nothing before
  /// the first observation.
  std::optional<double> toHost(std::uint32_t device_us) const;

  /// @brief Fitted host seconds per device second, minus 1 (e.g. 50e-6 = device 50 ppm slow).
  double drift() const { return slope_ - 1.0; }
  /// @brief Observations in the window.
  std::size_t samples() const { return samples_.size(); }
  /// @brief Forget everything (e.g. after a reconnect to a device that may have rebooted).
  void reset();

 private:
  double unwrap(std::uint32_t device_us) const;
  void fit();

  struct Sample {
    double device_s;
    double host_s;
  };
  double window_s_, max_drift_;
  std::deque<Sample> samples_;
  std::uint32_t last_raw_ = 0;
  double last_device_s_ = 0.0;  // unwrapped
  double slope_ = 1.0;
  double offset_ = 0.0;  // host = offset + slope * (device - origin)
  double origin_ = 0.0;
};

}  // namespace lms111
}  // namespace dormant_tree_modeling
