#include "dormant_tree_modeling/common/parallel.h"

#include <algorithm>
#include <atomic>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace dormant_tree_modeling {

void parallelFor(int n, const std::function<void(int)>& fn, int threads) {
  if (n <= 0)
    return;
  int workers = threads > 0 ? threads : static_cast<int>(std::thread::hardware_concurrency());
  workers = std::clamp(workers, 1, n);
  if (workers == 1) {
    for (int i = 0; i < n; ++i)
      fn(i);
    return;
  }
  std::atomic<int> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;
  const int block = std::max(1, n / (workers * 8));
  auto work = [&] {
    for (;;) {
      const int begin = next.fetch_add(block);
      if (begin >= n)
        return;
      for (int i = begin; i < std::min(n, begin + block); ++i) {
        try {
          fn(i);
        } catch (...) {
          std::lock_guard<std::mutex> lock(error_mutex);
          if (!error)
            error = std::current_exception();
          return;
        }
      }
    }
  };
  std::vector<std::thread> pool;
  for (int t = 1; t < workers; ++t)
    pool.emplace_back(work);
  work();
  for (auto& t : pool)
    t.join();
  if (error)
    std::rethrow_exception(error);
}

}  // namespace dormant_tree_modeling
