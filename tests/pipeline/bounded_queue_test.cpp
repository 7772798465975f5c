#include <gtest/gtest.h>

#include <thread>
#include <vector>

#include "rigcal/pipeline/bounded_queue.hpp"
#include "rigcal/pipeline/latency_histogram.hpp"

namespace rigcal::pipeline {
namespace {

TEST(BoundedQueue, LosslessPushDeliversEverythingInOrderAcrossThreads) {
  BoundedQueue<int> q(4);
  constexpr int kN = 20000;
  std::thread producer([&] {
    for (int i = 0; i < kN; ++i) ASSERT_TRUE(q.push(i));
  });
  for (int i = 0; i < kN; ++i) {
    const auto v = q.pop();
    ASSERT_TRUE(v.has_value());
    ASSERT_EQ(*v, i);
  }
  producer.join();
  EXPECT_EQ(q.dropped(), 0u);
  EXPECT_LE(q.maxDepth(), 4u);
}

TEST(BoundedQueue, DropOldestNeverBlocksAndCountsDrops) {
  BoundedQueue<int> q(3);
  for (int i = 0; i < 10; ++i) q.pushDropOldest(i);
  EXPECT_EQ(q.dropped(), 7u);
  EXPECT_EQ(*q.pop(), 7);
  EXPECT_EQ(*q.pop(), 8);
  EXPECT_EQ(*q.pop(), 9);
  EXPECT_FALSE(q.pop(std::chrono::microseconds(1000)).has_value());
}

TEST(BoundedQueue, DropOldestUnderAConcurrentConsumerKeepsOrderAndAccounting) {
  BoundedQueue<int> q(8);
  constexpr int kN = 50000;
  std::atomic<bool> done{false};
  std::vector<int> got;
  std::thread consumer([&] {
    while (!done.load() || q.depth() > 0)
      if (auto v = q.pop(std::chrono::microseconds(2000))) got.push_back(*v);
  });
  for (int i = 0; i < kN; ++i) q.pushDropOldest(i);
  done = true;
  consumer.join();
  EXPECT_EQ(got.size() + q.dropped(), std::size_t(kN));
  for (std::size_t i = 1; i < got.size(); ++i) ASSERT_LT(got[i - 1], got[i]);
}

TEST(BoundedQueue, CloseReleasesABlockedProducer) {
  BoundedQueue<int> q(1);
  ASSERT_TRUE(q.push(1));
  std::thread producer([&] { EXPECT_FALSE(q.push(2)); });
  std::this_thread::sleep_for(std::chrono::milliseconds(20));
  q.close();
  producer.join();
}

TEST(LatencyHistogram, QuantilesWithinThreePercent) {
  LatencyHistogram h;
  for (int i = 1; i <= 100000; ++i) h.record(std::int64_t(i) * 1000);  // 1 µs .. 100 ms uniform
  EXPECT_EQ(h.count(), 100000u);
  EXPECT_NEAR(double(h.quantile(0.5)), 50e6, 50e6 * 0.035);
  EXPECT_NEAR(double(h.quantile(0.99)), 99e6, 99e6 * 0.035);
  EXPECT_EQ(h.quantile(1.0), 100'000'000);
  EXPECT_EQ(h.min(), 1000);
  LatencyHistogram other;
  other.record(5);
  h.merge(other);
  EXPECT_EQ(h.min(), 5);
  EXPECT_EQ(h.quantile(0.0), 5);
  EXPECT_EQ(LatencyHistogram{}.quantile(0.5), 0);
}

}  // namespace
}  // namespace rigcal::pipeline
