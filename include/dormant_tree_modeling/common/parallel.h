#pragma once

#include <functional>

namespace dormant_tree_modeling {

/// @brief Run fn(i) for i in [0, n) on up to `threads` threads (0: all hardware threads).
/// Work is handed out in contiguous blocks; fn must be safe to call concurrently. The threads
/// are a pool started on first use; a nested call (from inside fn), or a call while another
/// thread's loop holds the pool, runs on the caller's thread. The first exception thrown by fn
/// stops the loop and is rethrown after all threads finished.
void parallelFor(int n, const std::function<void(int)>& fn, int threads = 0);

}  // namespace dormant_tree_modeling
