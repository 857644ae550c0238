#include "dormant_tree_modeling/simulation/lms111_model.h"

#include <algorithm>
#include <cmath>

#include "dormant_tree_modeling/common/error.h"

namespace dormant_tree_modeling {
namespace simulation {

namespace {

constexpr double DEG = M_PI / 180.0;
constexpr double RSSI_FULL_SCALE_ENERGY = 0.5;  // echo energy that saturates the 8-bit RSSI

void require(bool ok, const char* what) {
  if (!ok)
    throw Error(ErrorCode::INVALID_ARGUMENT, std::string("LMS111 model: ") + what);
}

struct SampleHit {
  double t;
  double energy;
  double incidence;  // rad
  Label label;
};

}  // namespace

int Lms111Config::beamCount() const {
  return static_cast<int>(std::lround((stop_angle_deg - start_angle_deg) / angular_resolution_deg));
}

std::vector<std::string> sensorVariantNames() {
  return {"ours", "thin_beam", "wide_beam", "far_noise"};
}

Lms111Config sensorVariant(const std::string& name) {
  Lms111Config c;
  if (name == "ours")
    return c;
  if (name == "thin_beam") {
    c.beam_samples = 1;
    return c;
  }
  if (name == "wide_beam") {
    c.beam_exit_diameter = 0.012;
    c.beam_divergence = 0.025;
    return c;
  }
  if (name == "far_noise") {
    c.range_noise_per_m = 0.002;
    c.echo_merge_distance = 1.2;
    return c;
  }
  std::string names;
  for (const auto& n : sensorVariantNames())
    names += (names.empty() ? "" : ", ") + n;
  throw Error(ErrorCode::INVALID_ARGUMENT,
              "unknown sensor variant '" + name + "' (known: " + names + ")");
}

void Lms111Config::validate() const {
  require(angular_resolution_deg == 0.25 || angular_resolution_deg == 0.5,
          "angular_resolution_deg must be 0.25 or 0.5");
  require(scan_frequency_hz == 25.0 || scan_frequency_hz == 50.0,
          "scan_frequency_hz must be 25 or 50");
  require((angular_resolution_deg == 0.25) == (scan_frequency_hz == 25.0),
          "the LMS111 pairs 0.25 deg with 25 Hz and 0.5 deg with 50 Hz");
  // The device's last beam is at 225 deg inclusive (1081 beams), so the exclusive stop may
  // lie one step beyond it.
  require(start_angle_deg >= -45.0 && stop_angle_deg <= 225.0 + angular_resolution_deg &&
              start_angle_deg < stop_angle_deg,
          "angles must satisfy -45 <= start < stop <= 225 deg + one step");
  require(min_range >= 0.0 && max_range > min_range, "need 0 <= min_range < max_range");
  require(range_noise_sigma >= 0.0, "range_noise_sigma must be >= 0");
  require(range_noise_per_m >= 0.0 && range_noise_per_m <= 0.05,
          "range_noise_per_m must be in [0, 0.05]");
  require(std::abs(range_bias) < 1.0, "range_bias must be within +/-1 m");
  require(beam_exit_diameter >= 0.0 && beam_divergence >= 0.0, "beam size must be >= 0");
  require(beam_samples == 1 || beam_samples == 7, "beam_samples must be 1 or 7");
  require(echo_merge_distance >= 0.0, "echo_merge_distance must be >= 0");
  require(detection_threshold > 0.0 && detection_threshold < 1.0,
          "detection_threshold must be in (0, 1)");
  require(grazing_dropout_start_deg < grazing_dropout_full_deg && grazing_dropout_full_deg <= 90.0,
          "need grazing_dropout_start_deg < grazing_dropout_full_deg <= 90");
}

Lms111Model::Lms111Model(const RayCaster& caster, const Lms111Config& config)
    : caster_(caster), config_(config) {
  config_.validate();
  footprint_.push_back(Eigen::Vector2d::Zero());
  if (config_.beam_samples == 7) {
    // Centre plus a ring at the radius that splits a uniform disc into equal-area parts.
    const double ring = std::sqrt(4.0 / 7.0) * 0.8;
    for (int k = 0; k < 6; ++k) {
      footprint_.emplace_back(ring * std::cos(k * M_PI / 3.0), ring * std::sin(k * M_PI / 3.0));
    }
  }
}

double Lms111Model::beamAngle(int j) const {
  return (config_.start_angle_deg + j * config_.angular_resolution_deg) * DEG;
}

ScanLine Lms111Model::scanLine(const Eigen::Isometry3d& laser_pose, Rng& rng) const {
  const int n = config_.beamCount();
  ScanLine line;
  line.ranges.assign(n, 0.0f);
  line.rssi.assign(n, 0);
  line.labels.assign(n, Label{});
  const Eigen::Matrix3d rot = laser_pose.linear();
  const Eigen::Vector3d origin = laser_pose.translation();
  const Eigen::Vector3d e1 = rot * Eigen::Vector3d::UnitY();  // across the scan plane
  const double exit_radius = 0.5 * config_.beam_exit_diameter;
  const double half_divergence = 0.5 * config_.beam_divergence;
  const double weight = 1.0 / static_cast<double>(footprint_.size());
  std::vector<SampleHit> hits;
  hits.reserve(footprint_.size());
  for (int j = 0; j < n; ++j) {
    const double phi = beamAngle(j);
    const Eigen::Vector3d dir = rot * Eigen::Vector3d(std::sin(phi), 0.0, -std::cos(phi));
    const Eigen::Vector3d e2 = rot * Eigen::Vector3d(std::cos(phi), 0.0, std::sin(phi));
    hits.clear();
    for (const auto& f : footprint_) {
      const Eigen::Vector3d offset = f.x() * e1 + f.y() * e2;
      Ray ray{origin + exit_radius * offset, (dir + half_divergence * offset).normalized()};
      const auto hit = caster_.cast(ray, 1e-4, config_.max_range + 1.0);
      if (!hit)
        continue;
      const double cos_inc = std::abs(hit->normal.dot(ray.direction));
      hits.push_back(SampleHit{hit->t, weight * hit->reflectivity * cos_inc,
                               std::acos(std::min(1.0, cos_inc)), hit->label});
    }
    if (hits.empty())
      continue;
    std::sort(hits.begin(), hits.end(),
              [](const SampleHit& a, const SampleHit& b) { return a.t < b.t; });
    // The first echo strong enough to trigger the receiver wins.
    for (std::size_t g = 0; g < hits.size();) {
      std::size_t end = g + 1;
      while (end < hits.size() && hits[end].t - hits[end - 1].t < config_.echo_merge_distance)
        ++end;
      double energy = 0.0, weighted_t = 0.0, best = -1.0;
      const SampleHit* dominant = &hits[g];
      for (std::size_t k = g; k < end; ++k) {
        energy += hits[k].energy;
        weighted_t += hits[k].energy * hits[k].t;
        if (hits[k].energy > best) {
          best = hits[k].energy;
          dominant = &hits[k];
        }
      }
      if (energy < config_.detection_threshold) {
        g = end;
        continue;
      }
      const double inc_deg = dominant->incidence / DEG;
      const double p_drop =
          std::clamp((inc_deg - config_.grazing_dropout_start_deg) /
                         (config_.grazing_dropout_full_deg - config_.grazing_dropout_start_deg),
                     0.0, 1.0);
      if (p_drop > 0.0 && rng.bernoulli(p_drop))
        break;
      const double true_range = weighted_t / energy;
      const double sigma = config_.range_noise_sigma + config_.range_noise_per_m * true_range;
      const double range = true_range + config_.range_bias + rng.normal(0.0, sigma);
      if (range >= config_.min_range && range <= config_.max_range) {
        line.ranges[j] = static_cast<float>(range);
        line.rssi[j] = static_cast<std::uint8_t>(
            std::clamp(std::lround(255.0 * energy / RSSI_FULL_SCALE_ENERGY), 1L, 255L));
        line.labels[j] = dominant->label;
      }
      break;
    }
  }
  return line;
}

}  // namespace simulation
}  // namespace dormant_tree_modeling
