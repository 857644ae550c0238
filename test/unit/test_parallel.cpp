// parallelFor: every index exactly once, nested and concurrent calls, exceptions.
#include <gtest/gtest.h>

#include <atomic>
#include <stdexcept>
#include <thread>
#include <vector>

#include "dormant_tree_modeling/common/parallel.h"

using dormant_tree_modeling::parallelFor;

TEST(ParallelFor, RunsEveryIndexOnce) {
  for (const int n : {1, 2, 7, 1000, 100000}) {
    std::vector<std::atomic<int>> hits(n);
    parallelFor(n, [&](int i) { hits[i].fetch_add(1); });
    int wrong = 0;
    for (const auto& h : hits)
      wrong += h.load() != 1;
    EXPECT_EQ(wrong, 0) << "n = " << n;
  }
}

TEST(ParallelFor, NothingToDo) {
  int calls = 0;
  parallelFor(0, [&](int) { ++calls; });
  parallelFor(-3, [&](int) { ++calls; });
  EXPECT_EQ(calls, 0);
}

TEST(ParallelFor, OneThreadRunsInOrderOnTheCaller) {
  const auto caller = std::this_thread::get_id();
  std::vector<int> order;
  bool elsewhere = false;
  parallelFor(
      50,
      [&](int i) {
        order.push_back(i);
        elsewhere |= std::this_thread::get_id() != caller;
      },
      1);
  ASSERT_EQ(order.size(), 50u);
  for (int i = 0; i < 50; ++i)
    EXPECT_EQ(order[i], i);
  EXPECT_FALSE(elsewhere);
}

TEST(ParallelFor, NestedCallsComplete) {
  std::atomic<long> sum{0};
  parallelFor(40, [&](int i) { parallelFor(100, [&](int j) { sum += i * 100 + j; }); });
  const long n = 40 * 100;
  EXPECT_EQ(sum.load(), n * (n - 1) / 2);
}

TEST(ParallelFor, ConcurrentCallersAllComplete) {
  std::vector<std::thread> callers;
  std::vector<long> sums(4, 0);
  for (int c = 0; c < 4; ++c) {
    callers.emplace_back([&sums, c] {
      for (int round = 0; round < 50; ++round) {
        std::atomic<long> sum{0};
        parallelFor(1000, [&](int i) { sum += i; });
        sums[c] += sum.load();
      }
    });
  }
  for (auto& t : callers)
    t.join();
  for (const long s : sums)
    EXPECT_EQ(s, 50L * 999 * 1000 / 2);
}

TEST(ParallelFor, RethrowsTheFirstExceptionAndStaysUsable) {
  EXPECT_THROW(parallelFor(10000,
                           [](int i) {
                             if (i == 1234)
                               throw std::runtime_error("bad index");
                           }),
               std::runtime_error);
  std::atomic<int> count{0};
  parallelFor(1000, [&](int) { ++count; });
  EXPECT_EQ(count.load(), 1000);
}
