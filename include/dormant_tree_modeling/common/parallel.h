#pragma once

#include <functional>

namespace dormant_tree_modeling {

/// @brief Run fn(i) for i in [0, n) on up to `threads` threads (0: all hardware threads).
/// Work is handed out in contiguous blocks; fn must be safe to call concurrently. The first
/// exception thrown by fn is rethrown after all threads finished.
void parallelFor(int n, const std::function<void(int)>& fn, int threads = 0);

}  // namespace dormant_tree_modeling
