#pragma once

#include <benchmark/benchmark.h>

#include "peak_rss.h"

namespace dormant_tree_modeling {
namespace bench {

/// @brief Report the process's peak resident memory so far as the counter `peak_rss_MiB`.
inline void reportPeakMemory(benchmark::State& state) {
  state.counters["peak_rss_MiB"] = peakRssMiB();
}

}  // namespace bench
}  // namespace dormant_tree_modeling
