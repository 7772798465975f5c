// The view's binary update encoding, its [ADDR:]PORT parsing and its bounded dropping queue.
#include <gtest/gtest.h>

#include <thread>

#include "rigcal/view/update_encoding.hpp"
#include "rigcal/view/update_queue.hpp"
#include "rigcal/view/view_endpoint.hpp"

namespace rigcal::view {
namespace {

TEST(UpdateEncoding, RoundTripsEveryKind) {
  for (auto kind : {UpdateKind::kMapPoints, UpdateKind::kTrajectory, UpdateKind::kCandidate, UpdateKind::kSelected,
                    UpdateKind::kCloudBefore, UpdateKind::kCloudAfter}) {
    std::vector<float> values;
    for (std::size_t i = 0; i < 5 * strideOf(kind); ++i) values.push_back(float(i) * 0.5f - 3.0f);
    const std::string m = encodeUpdate(kind, 2, values);
    EXPECT_EQ(m.size(), kHeaderBytes + values.size() * 4);
    const auto d = decodeUpdate(m);
    ASSERT_TRUE(d);
    EXPECT_EQ(d->kind, kind);
    EXPECT_EQ(d->lane, 2);
    EXPECT_EQ(d->values, values);
  }
  // The header a browser reads: kind, lane, little-endian count.
  const std::string m = encodeUpdate(UpdateKind::kTrajectory, kNoLane, {1, 2, 3, 1, 4, 5, 6, 2});
  EXPECT_EQ(std::uint8_t(m[0]), 2);
  EXPECT_EQ(std::uint8_t(m[1]), 255);
  EXPECT_EQ(std::uint8_t(m[4]), 2);
  EXPECT_EQ(m[5] | m[6] | m[7], 0);
}

TEST(UpdateEncoding, RefusesMessagesThatAreNotUpdates) {
  EXPECT_FALSE(decodeUpdate(""));
  EXPECT_FALSE(decodeUpdate("1234567"));
  std::string m = encodeUpdate(UpdateKind::kMapPoints, 0, {1, 2, 3});
  EXPECT_FALSE(decodeUpdate(m.substr(0, m.size() - 1)));  // count and size disagree
  m[0] = 9;
  EXPECT_FALSE(decodeUpdate(m));
  std::string huge = encodeUpdate(UpdateKind::kMapPoints, 0, {});
  huge[7] = char(0x7f);  // a count far beyond the bytes
  EXPECT_FALSE(decodeUpdate(huge));
}

TEST(ViewEndpoint, ParsesPortOrAddressAndPort) {
  auto e = parseViewEndpoint("8080");
  EXPECT_EQ(e.address, "127.0.0.1");
  EXPECT_EQ(e.port, 8080);
  EXPECT_TRUE(e.loopback());
  e = parseViewEndpoint("0.0.0.0:9000");
  EXPECT_EQ(e.address, "0.0.0.0");
  EXPECT_EQ(e.port, 9000);
  EXPECT_FALSE(e.loopback());
  e = parseViewEndpoint("[::1]:80");
  EXPECT_EQ(e.address, "::1");
  EXPECT_TRUE(e.loopback());
  EXPECT_TRUE(parseViewEndpoint("127.0.0.2:1").loopback());
  for (const char* bad : {"", "x", "80a", "65536", "-1", "host:80", "1.2.3:80", ":", "127.0.0.1:"}) {
    try {
      parseViewEndpoint(bad);
      ADD_FAILURE() << "accepted '" << bad << "'";
    } catch (const std::invalid_argument& err) {
      EXPECT_NE(std::string(err.what()).find("--view"), std::string::npos);
    }
  }
}

TEST(UpdateQueue, DropsAndCountsWhenFullNeverWaits) {
  UpdateQueue<int> q(4);
  for (int i = 0; i < 10; ++i) q.tryPush(i);
  EXPECT_EQ(q.size(), 4u);
  EXPECT_EQ(q.dropped(), 6u);
  for (int i = 0; i < 4; ++i) EXPECT_EQ(q.pop(std::chrono::milliseconds(0)), i);  // the oldest kept
  EXPECT_FALSE(q.pop(std::chrono::milliseconds(1)));
  q.close();
  EXPECT_FALSE(q.tryPush(1));
  EXPECT_EQ(q.dropped(), 7u);
}

TEST(UpdateQueue, ManyProducersOneConsumer) {
  UpdateQueue<int> q(64);
  std::atomic<int> received{0};
  std::atomic<bool> closed{false};
  std::thread consumer([&] {
    while (true) {
      if (q.pop(std::chrono::milliseconds(20))) received.fetch_add(1);
      else if (closed.load()) return;  // closed and drained
    }
  });
  std::vector<std::thread> producers;
  for (int p = 0; p < 4; ++p)
    producers.emplace_back([&] {
      for (int i = 0; i < 2000; ++i) q.tryPush(i);
    });
  for (auto& t : producers) t.join();
  q.close();
  closed.store(true);
  consumer.join();
  EXPECT_EQ(std::uint64_t(received.load()) + q.dropped(), 8000u);
}

}  // namespace
}  // namespace rigcal::view
