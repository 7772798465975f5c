#include "rigcal/registration/parallel.hpp"

#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <stdexcept>
#include <thread>
#include <vector>

#include "rigcal/core/worker_pool.hpp"
#include "rigcal/registration/deadline.hpp"

namespace rigcal::registration {
namespace {

TEST(Parallel, ReductionIsBitIdenticalForAnyThreadCount) {
  // Terms of wildly different magnitude: any change in summation order changes the last bits.
  std::vector<double> v(100000);
  for (std::size_t i = 0; i < v.size(); ++i) v[i] = std::sin(static_cast<double>(i)) * std::pow(10.0, i % 17);
  auto sum = [&](int threads) {
    return parallelReduce(chunkCount(v.size(), 512), threads, 0.0, [&](std::size_t t) {
      double s = 0.0;
      for (std::size_t i = t * 512; i < std::min(v.size(), (t + 1) * 512); ++i) s += v[i];
      return s;
    });
  };
  const double one = sum(1);
  EXPECT_EQ(one, sum(2));
  EXPECT_EQ(one, sum(3));
}

TEST(Parallel, EveryTaskRunsOnceAndErrorsPropagate) {
  std::vector<int> hits(1000, 0);
  parallelFor(hits.size(), 2, [&](std::size_t t) { ++hits[t]; });
  for (int h : hits) EXPECT_EQ(h, 1);
  EXPECT_THROW(parallelFor(100, 2, [](std::size_t t) {
                 if (t == 50) throw std::runtime_error("task failed");
               }),
               std::runtime_error);
  parallelFor(0, 2, [](std::size_t) { FAIL(); });
}

TEST(WorkerPool, KeepsItsThreadsAcrossCallsWithParallelForsContract) {
  WorkerPool pool(2);
  EXPECT_EQ(pool.threads(), 2);
  // Many short calls on the same threads (the lidar-pose objective's pattern): each task exactly once.
  std::vector<int> hits(64, 0);
  for (int call = 0; call < 2000; ++call) pool.parallelFor(hits.size(), [&](std::size_t t) { ++hits[t]; });
  for (int h : hits) EXPECT_EQ(h, 2000);
  // The first exception comes back to the caller, and the pool still works afterwards.
  EXPECT_THROW(pool.parallelFor(100, [](std::size_t t) {
                 if (t == 50) throw std::runtime_error("task failed");
               }),
               std::runtime_error);
  std::vector<int> after(10, 0);
  pool.parallelFor(after.size(), [&](std::size_t t) { after[t] = static_cast<int>(t); });
  for (std::size_t t = 0; t < after.size(); ++t) EXPECT_EQ(after[t], static_cast<int>(t));
  pool.parallelFor(0, [](std::size_t) { FAIL(); });
  WorkerPool single(1);
  EXPECT_EQ(single.threads(), 1);
  int sum = 0;
  single.parallelFor(4, [&](std::size_t t) { sum += static_cast<int>(t); });
  EXPECT_EQ(sum, 6);
}

TEST(Deadline, NeverAfterAndCancel) {
  EXPECT_EQ(Deadline().check(), StopReason::kNone);
  EXPECT_EQ(Deadline::never().check(), StopReason::kNone);
  EXPECT_EQ(Deadline::after(std::chrono::hours(1)).check(), StopReason::kNone);
  EXPECT_EQ(Deadline::after(std::chrono::milliseconds(-1)).check(), StopReason::kTimeout);
  const Deadline soon = Deadline::after(std::chrono::milliseconds(5));
  std::this_thread::sleep_for(std::chrono::milliseconds(10));
  EXPECT_TRUE(soon.expired());

  CancelToken token;
  const Deadline d = Deadline::never(&token);
  EXPECT_FALSE(d.expired());
  std::thread other([&] { token.cancel(); });
  other.join();
  EXPECT_EQ(d.check(), StopReason::kCancelled);
  token.reset();
  EXPECT_FALSE(d.expired());
}

}  // namespace
}  // namespace rigcal::registration
