#include <gtest/gtest.h>

#include "rigcal/core/scan.hpp"

namespace rigcal {
namespace {

Scan threePoints() {
  Scan s;
  s.stamp_ns = 1'000'000'000;
  for (int i = 0; i < 3; ++i)
    s.push_back(Point{float(i), float(-i), 0.5f, float(10 * i), std::uint16_t(i),
                      s.stamp_ns + 1000 * i, std::uint8_t(i % 2)});
  return s;
}

TEST(Scan, PushBackStoresOffsetsRelativeToStamp) {
  const Scan s = threePoints();
  ASSERT_EQ(s.size(), 3u);
  EXPECT_EQ(s.offset_ns[2], 2000u);
  EXPECT_EQ(s.pointTime(2), 1'000'002'000);
  const Point p = s.point(1);
  EXPECT_EQ(p.x, 1.0f);
  EXPECT_EQ(p.ring, 1);
  EXPECT_EQ(p.return_index, 1);
}

TEST(Scan, FilterKeepsEveryColumnAligned) {
  Scan s = threePoints();
  s.filter([&](std::size_t i) { return i != 1; });
  ASSERT_EQ(s.size(), 2u);
  EXPECT_EQ(s.x[1], 2.0f);
  EXPECT_EQ(s.intensity[1], 20.0f);
  EXPECT_EQ(s.ring[1], 2);
  EXPECT_EQ(s.offset_ns[1], 2000u);
  EXPECT_EQ(s.return_index[1], 0);
  EXPECT_EQ(s.return_index.size(), 2u);
}

TEST(Scan, ClearEmptiesPointsAndLossCount) {
  Scan s = threePoints();
  s.missing_packets = 4;
  s.clear();
  EXPECT_TRUE(s.empty());
  EXPECT_EQ(s.missing_packets, 0u);
}

}  // namespace
}  // namespace rigcal
