// Azimuth ordering of held-back points (azimuth_order.hpp).
#include <gtest/gtest.h>

#include "rigcal/drivers/hesai/azimuth_order.hpp"

namespace rigcal::drivers::hesai {
namespace {

Point tagged(int tag) {
  Point p;
  p.ring = static_cast<std::uint16_t>(tag);
  return p;
}

std::vector<int> tags(const DecodedPacket& out) {
  std::vector<int> t;
  for (const Point& p : out.points) t.push_back(p.ring);
  return t;
}

TEST(AzimuthOrder, BucketCentresAndTheCutConvention) {
  EXPECT_FLOAT_EQ(AzimuthOrder::bucketAzimuthDeg(0), 0.005f);
  EXPECT_FLOAT_EQ(AzimuthOrder::bucketAzimuthDeg(-1), 359.995f);  // holds azimuths in (359.99°, 360°]
  EXPECT_FLOAT_EQ(AzimuthOrder::bucketAzimuthDeg(36000 * 5 + 9000), 90.005f);
}

TEST(AzimuthOrder, InterleavedRunsComeOutSorted) {
  AzimuthOrder order;
  DecodedPacket out;
  // Run 1 at buckets 10, 20, 30; run 2 at 15, 25, 35 (overlapping channel offsets).
  order.push(tagged(10), 10), order.push(tagged(20), 20), order.push(tagged(30), 30), order.endRun();
  order.release(12, out);
  EXPECT_EQ(tags(out), (std::vector<int>{10}));
  order.push(tagged(15), 15), order.push(tagged(25), 25), order.push(tagged(35), 35), order.endRun();
  out.reset();
  order.release(27, out);
  EXPECT_EQ(tags(out), (std::vector<int>{15, 20, 25}));
  EXPECT_EQ(order.held(), 2u);
  out.reset();
  order.releaseAll(out);
  EXPECT_EQ(tags(out), (std::vector<int>{30, 35}));
  ASSERT_EQ(out.azimuth_deg.size(), 2u);
  EXPECT_FLOAT_EQ(out.azimuth_deg[0], 0.305f);
  EXPECT_EQ(order.held(), 0u);
}

TEST(AzimuthOrder, LatePointsAreEmittedFirstAtTheNextRelease) {
  AzimuthOrder order;
  DecodedPacket out;
  order.push(tagged(100), 100), order.endRun();
  order.release(100, out);
  // A late run with buckets below what was released, and one above.
  order.push(tagged(90), 90), order.push(tagged(105), 105), order.endRun();
  order.push(tagged(102), 102), order.endRun();
  out.reset();
  order.release(110, out);
  EXPECT_EQ(tags(out), (std::vector<int>{90, 102, 105}));
}

TEST(AzimuthOrder, WideRangesFallBackToASort) {
  AzimuthOrder order;
  DecodedPacket out;
  order.push(tagged(1), 0), order.push(tagged(3), 500000), order.endRun();
  order.push(tagged(2), 1000), order.endRun();
  order.release(10'000'000, out);
  EXPECT_EQ(tags(out), (std::vector<int>{1, 2, 3}));
}

TEST(AzimuthOrder, SteadyStateReusesMemory) {
  AzimuthOrder order;
  DecodedPacket out;
  std::int64_t bucket = 0;
  std::size_t emitted = 0;
  for (int run = 0; run < 20000; ++run, bucket += 40) {
    for (int k = 0; k < 100; ++k) order.push(tagged(k), bucket - 1000 + 20 * k);
    order.endRun();
    out.reset();
    order.release(bucket - 1000, out);
    emitted += out.points.size();
    for (std::size_t i = 1; i < out.azimuth_deg.size(); ++i)
      if (out.azimuth_deg[i] < out.azimuth_deg[i - 1] && out.azimuth_deg[i - 1] - out.azimuth_deg[i] < 180.f)
        FAIL() << "unsorted at run " << run;
  }
  out.reset();
  order.releaseAll(out);
  emitted += out.points.size();
  EXPECT_EQ(emitted, 20000u * 100u);
}

}  // namespace
}  // namespace rigcal::drivers::hesai
