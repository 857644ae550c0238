#pragma once

#include <benchmark/benchmark.h>
#include <sys/resource.h>

namespace dormant_tree_modeling {
namespace bench {

/// @brief Report the process's peak resident memory so far as the counter `peak_rss_MiB`.
inline void reportPeakMemory(benchmark::State& state) {
  rusage usage{};
  getrusage(RUSAGE_SELF, &usage);
  state.counters["peak_rss_MiB"] = static_cast<double>(usage.ru_maxrss) / 1024.0;
}

}  // namespace bench
}  // namespace dormant_tree_modeling
