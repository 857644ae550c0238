#pragma once

#include <cmath>
#include <cstdint>

namespace dormant_tree_modeling {

/// @brief Seeded random numbers that give the same sequence on every platform and standard
/// library (std:: distributions are implementation-defined, so they are not used).
///
/// SplitMix64 state stepping; uniform doubles from the top 53 bits; normals by Box-Muller.
class Rng {
 public:
  /// @param seed any value; equal seeds give equal sequences
  explicit Rng(std::uint64_t seed) : state_(seed) {}

  /// @brief An independent stream derived from a seed and up to three indices (e.g. view, line).
  static Rng derive(std::uint64_t seed, std::uint64_t a, std::uint64_t b = 0, std::uint64_t c = 0) {
    Rng r(seed ^ 0x6a09e667f3bcc909ULL);
    r.state_ ^= r.next() + a * 0x9e3779b97f4a7c15ULL;
    r.state_ ^= r.next() + b * 0xbf58476d1ce4e5b9ULL;
    r.state_ ^= r.next() + c * 0x94d049bb133111ebULL;
    return r;
  }

  /// @brief Next raw 64-bit value.
  std::uint64_t next() {
    std::uint64_t z = (state_ += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
  }

  /// @brief Uniform in [0, 1).
  double uniform() { return static_cast<double>(next() >> 11) * 0x1.0p-53; }

  /// @brief Uniform in [lo, hi).
  double uniform(double lo, double hi) { return lo + (hi - lo) * uniform(); }

  /// @brief Uniform integer in [lo, hi] (inclusive).
  int uniformInt(int lo, int hi) {
    return lo + static_cast<int>(uniform() * static_cast<double>(hi - lo + 1));
  }

  /// @brief True with probability p.
  bool bernoulli(double p) { return uniform() < p; }

  /// @brief Standard normal N(0, 1).
  double normal() {
    if (has_spare_) {
      has_spare_ = false;
      return spare_;
    }
    double u1 = uniform();
    while (u1 <= 0.0)
      u1 = uniform();
    const double u2 = uniform();
    const double r = std::sqrt(-2.0 * std::log(u1));
    spare_ = r * std::sin(2.0 * M_PI * u2);
    has_spare_ = true;
    return r * std::cos(2.0 * M_PI * u2);
  }

  /// @brief Normal N(mean, sigma^2).
  double normal(double mean, double sigma) { return mean + sigma * normal(); }

 private:
  std::uint64_t state_;
  double spare_ = 0.0;
  bool has_spare_ = false;
};

}  // namespace dormant_tree_modeling
