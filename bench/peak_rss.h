#pragma once

#include <sys/resource.h>

namespace dormant_tree_modeling {
namespace bench {

/// @brief The process's peak resident memory so far, MiB. Free of Google Benchmark, so the
/// plain accuracy programs can use it too.
inline double peakRssMiB() {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  return static_cast<double>(usage.ru_maxrss) / 1024.0;
}

}  // namespace bench
}  // namespace dormant_tree_modeling
