#include "dormant_tree_modeling/common/parallel.h"

#include <algorithm>
#include <atomic>
#include <condition_variable>
#include <exception>
#include <mutex>
#include <thread>
#include <vector>

namespace dormant_tree_modeling {

namespace {

/// True on a thread while it runs a job's indices, the caller's included: a nested loop there
/// runs serially (it must not wait for workers that are busy running its own caller).
thread_local bool in_job = false;

/// One job of parallelFor: indices handed out in blocks from an atomic counter.
struct Job {
  int n = 0;
  int block = 1;
  const std::function<void(int)>* fn = nullptr;
  std::atomic<int> next{0};
  std::exception_ptr error;
  std::mutex error_mutex;

  void run() {
    const bool outer = in_job;
    in_job = true;
    runBlocks();
    in_job = outer;
  }

 private:
  void runBlocks() {
    for (;;) {
      const int begin = next.fetch_add(block);
      if (begin >= n)
        return;
      for (int i = begin; i < std::min(n, begin + block); ++i) {
        try {
          (*fn)(i);
        } catch (...) {
          std::lock_guard<std::mutex> lock(error_mutex);
          if (!error)
            error = std::current_exception();
          next.store(n);  // the others stop at their next block
          return;
        }
      }
    }
  }
};

/// Workers started once and kept: starting threads for every call cost more than the work of
/// many calls (k-means runs one parallel loop per iteration), and its cost varies on a VM.
class Pool {
 public:
  explicit Pool(int workers) {
    for (int t = 0; t < workers; ++t)
      threads_.emplace_back([this] { loop(); });
  }

  ~Pool() {
    {
      std::lock_guard<std::mutex> lock(mutex_);
      stop_ = true;
    }
    wake_.notify_all();
    for (auto& t : threads_)
      t.join();
  }

  int size() const { return static_cast<int>(threads_.size()); }

  /// Runs job on the caller and `helpers` workers; false when another caller holds the pool.
  bool tryRun(Job& job, int helpers) {
    std::unique_lock<std::mutex> busy(busy_, std::try_to_lock);
    if (!busy.owns_lock())
      return false;
    {
      std::lock_guard<std::mutex> lock(mutex_);
      job_ = &job;
      wanted_ = std::min(helpers, size());
      active_ = 0;
      ++generation_;
    }
    wake_.notify_all();
    job.run();
    std::unique_lock<std::mutex> lock(mutex_);
    // No new helper may join once the caller is done; wait for those that did.
    wanted_ = 0;
    done_.wait(lock, [this] { return active_ == 0; });
    job_ = nullptr;
    return true;
  }

 private:
  void loop() {
    std::uint64_t seen = 0;
    std::unique_lock<std::mutex> lock(mutex_);
    for (;;) {
      wake_.wait(lock, [&] { return stop_ || (generation_ != seen && wanted_ > 0); });
      if (stop_)
        return;
      seen = generation_;
      --wanted_;
      ++active_;
      Job* job = job_;
      lock.unlock();
      job->run();
      lock.lock();
      if (--active_ == 0)
        done_.notify_all();
    }
  }

  std::vector<std::thread> threads_;
  std::mutex busy_;   // one parallelFor at a time uses the workers
  std::mutex mutex_;  // guards the fields below
  std::condition_variable wake_, done_;
  Job* job_ = nullptr;
  std::uint64_t generation_ = 0;
  int wanted_ = 0;
  int active_ = 0;
  bool stop_ = false;
};

/// The machine's hardware threads, read once: std::thread::hardware_concurrency reads sysfs on
/// every call, and parallelFor is called thousands of times per model.
int hardwareThreads() {
  static const int threads = std::max(1, static_cast<int>(std::thread::hardware_concurrency()));
  return threads;
}

Pool& pool() {
  static Pool instance(std::max(1, hardwareThreads() - 1));
  return instance;
}

}  // namespace

void parallelFor(int n, const std::function<void(int)>& fn, int threads) {
  if (n <= 0)
    return;
  int workers = threads > 0 ? threads : hardwareThreads();
  workers = std::clamp(workers, 1, n);
  Job job;
  job.n = n;
  job.fn = &fn;
  job.block = std::max(1, n / (workers * 8));
  // Serial when asked, inside a worker (a nested loop must not wait for the workers it runs
  // on) or when the workers are busy with another caller's loop.
  if (workers == 1 || in_job || !pool().tryRun(job, workers - 1))
    job.run();
  if (job.error)
    std::rethrow_exception(job.error);
}

}  // namespace dormant_tree_modeling
