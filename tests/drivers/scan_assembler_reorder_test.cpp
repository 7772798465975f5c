// The reorder window of ScanAssembler: UDP may deliver a sensor's packets slightly out of order.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <random>

#include "allocation_counter.hpp"
#include "rigcal/drivers/scan_assembler.hpp"

namespace rigcal::drivers {
namespace {

// Packet k of a stream: 36 points one degree apart starting at (k % 10) * 36°, 1 µs apart, keyed k.
// Every point's x encodes (k, i) so that scans can be compared point by point.
DecodedPacket streamPacket(int k) {
  DecodedPacket p;
  p.order_key = std::uint64_t(k);
  p.packet_time_ns = TimeNs(k) * 36'000;
  for (int i = 0; i < 36; ++i) {
    p.points.push_back(Point{float(k * 100 + i), 0, 0, 0, 0, p.packet_time_ns + i * 1000, 0});
    p.azimuth_deg.push_back(std::fmod(float(k % 10) * 36.f + float(i), 360.f));
  }
  return p;
}

struct Outcome {
  std::vector<Scan> scans;
  AssemblerStats stats;
};

Outcome assemble(const std::vector<int>& order, std::size_t window, bool move = false) {
  Outcome run;
  AssemblerConfig config{90.0};
  config.reorder_window = window;
  ScanAssembler a("s", config, [&](Scan&& s) { run.scans.push_back(std::move(s)); });
  for (int k : order) {
    DecodedPacket p = streamPacket(k);
    if (move)
      a.add(std::move(p));
    else
      a.add(p);
  }
  a.flush();
  run.stats = a.stats();
  return run;
}

void expectSameScans(const std::vector<Scan>& a, const std::vector<Scan>& b) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t s = 0; s < a.size(); ++s) {
    EXPECT_EQ(a[s].sequence, b[s].sequence);
    EXPECT_EQ(a[s].stamp_ns, b[s].stamp_ns);
    EXPECT_EQ(a[s].x, b[s].x) << "scan " << s;
    EXPECT_EQ(a[s].offset_ns, b[s].offset_ns) << "scan " << s;
  }
}

std::vector<int> inOrder(int n) {
  std::vector<int> v(std::size_t(n), 0);
  for (int k = 0; k < n; ++k) v[std::size_t(k)] = k;
  return v;
}

TEST(ScanAssemblerReorder, ShuffledWithinTheWindowGivesTheSameScansAsInOrder) {
  const Outcome reference = assemble(inOrder(40), 0);
  ASSERT_EQ(reference.scans.size(), 5u);
  std::mt19937 rng(7);
  for (int trial = 0; trial < 20; ++trial) {
    // Shuffle inside consecutive blocks of 8: no packet moves by more than 7 places.
    std::vector<int> order = inOrder(40);
    for (std::size_t b = 0; b < order.size(); b += 8)
      std::shuffle(order.begin() + std::ptrdiff_t(b), order.begin() + std::ptrdiff_t(std::min(b + 8, order.size())), rng);
    const Outcome shuffled = assemble(order, 8, trial % 2 == 1);
    expectSameScans(shuffled.scans, reference.scans);
    EXPECT_EQ(shuffled.stats.late_dropped, 0u);
    EXPECT_GT(shuffled.stats.reordered, 0u);
    EXPECT_EQ(shuffled.stats.packets, 40u);
  }
}

TEST(ScanAssemblerReorder, APacketDelayedByExactlyTheWindowStillFitsIn) {
  std::vector<int> order = inOrder(30);
  order.erase(order.begin() + 5);
  order.insert(order.begin() + 5 + 8, 5);  // packet 5 arrives after 6..13: displaced by 8
  expectSameScans(assemble(order, 8).scans, assemble(inOrder(30), 0).scans);
}

TEST(ScanAssemblerReorder, APacketLaterThanTheWindowIsDroppedAndCounted) {
  std::vector<int> order = inOrder(30);
  order.erase(order.begin() + 5);
  order.insert(order.begin() + 5 + 9, 5);  // displaced by 9 with a window of 8: too late
  const Outcome run = assemble(order, 8);
  EXPECT_EQ(run.stats.late_dropped, 1u);
  EXPECT_EQ(run.stats.packets, 30u);
  std::size_t points = 0;
  for (const Scan& s : run.scans) {
    points += s.size();
    for (float x : s.x) EXPECT_FALSE(x >= 500.f && x < 600.f) << "late packet 5 must not appear";
  }
  EXPECT_EQ(points, 29u * 36u);
}

TEST(ScanAssemblerReorder, WithoutAWindowPacketsPassInArrivalOrder) {
  const Outcome run = assemble({0, 2, 1, 3}, 0);
  ASSERT_EQ(run.scans.size(), 3u);  // the late packet 1 lands inside the second sweep
  EXPECT_EQ(run.stats.late_dropped, 0u);
  EXPECT_EQ(run.stats.reordered, 1u);
  EXPECT_EQ(run.scans[0].x[36], 200.f) << "packet 2 was taken where it arrived";
}

TEST(ScanAssemblerReorder, AKeyThatGoesBackForGoodRestartsTheOrdering) {
  // A sensor restart: keys 100.. then 0.. again. The window (4) drops 4 packets as late, then restarts.
  std::vector<Scan> scans;
  AssemblerConfig config{90.0};
  config.reorder_window = 4;
  ScanAssembler a("s", config, [&](Scan&& s) { scans.push_back(std::move(s)); });
  for (int k = 0; k < 10; ++k) {
    DecodedPacket p = streamPacket(k);
    p.order_key = std::uint64_t(100 + k);
    a.add(p);
  }
  for (int k = 10; k < 30; ++k) {
    DecodedPacket p = streamPacket(k);
    p.order_key = std::uint64_t(k - 10);
    a.add(p);
  }
  a.flush();
  EXPECT_EQ(a.stats().late_dropped, 4u);
  EXPECT_EQ(a.stats().key_resets, 1u);
  std::size_t points = 0;
  for (const Scan& s : scans) points += s.size();
  EXPECT_EQ(points, 26u * 36u);
}

TEST(ScanAssemblerReorder, FlushStartsAFreshOrderForTheNextInput) {
  std::vector<Scan> scans;
  ScanAssembler a("s", AssemblerConfig{90.0}, [&](Scan&& s) { scans.push_back(std::move(s)); });
  for (int k = 10; k < 20; ++k) a.add(streamPacket(k));
  a.flush();
  for (int k = 0; k < 10; ++k) a.add(streamPacket(k));  // a replay loop starting over
  a.flush();
  EXPECT_EQ(a.stats().late_dropped, 0u);
  std::size_t points = 0;
  for (const Scan& s : scans) points += s.size();
  EXPECT_EQ(points, 20u * 36u);
}

TEST(ScanAssemblerReorder, SteadyStateAllocatesNothingBetweenSweeps) {
  RIGCAL_REQUIRE_ALLOCATION_COUNTING();
  std::vector<Scan> scans;
  scans.reserve(16);
  AssemblerConfig config{90.0};
  ScanAssembler a("s", config, [&](Scan&& s) { scans.push_back(std::move(s)); });
  // Packets of one turn cover 0..359°; the cut at 90° falls in packet k%10 == 2.
  std::vector<DecodedPacket> packets;
  for (int k = 0; k < 60; ++k) packets.push_back(streamPacket(k));
  std::vector<int> order = inOrder(60);
  std::mt19937 rng(3);
  for (std::size_t b = 0; b < order.size(); b += 4)
    std::shuffle(order.begin() + std::ptrdiff_t(b), order.begin() + std::ptrdiff_t(b + 4), rng);
  // Arrival i releases packet i - 8 (nothing is late). Up to arrival 30 (releasing packet 22, which
  // holds the third cut), two full turns warm the window's and the sweep's buffers up.
  std::size_t i = 0;
  for (; i <= 30; ++i) a.add(packets[std::size_t(order[i])]);
  const std::size_t scans_before = scans.size();
  // Arrivals 31..39 release packets 23..31: no cut, so nothing may allocate.
  test::AllocationCounter::start();
  for (; i < 40; ++i) a.add(packets[std::size_t(order[i])]);
  const std::uint64_t during = test::AllocationCounter::stop();
  EXPECT_EQ(scans.size(), scans_before) << "no sweep was emitted in the measured stretch";
  EXPECT_EQ(during, 0u) << "add() allocated in steady state";
  for (; i < 60; ++i) a.add(packets[std::size_t(order[i])]);
  a.flush();
  EXPECT_EQ(a.stats().late_dropped, 0u);
}

TEST(ScanAssemblerReorder, MalformedAndIgnoredPacketsBypassTheWindow) {
  std::vector<Scan> scans;
  ScanAssembler a("s", AssemblerConfig{}, [&](Scan&& s) { scans.push_back(std::move(s)); });
  DecodedPacket bad;
  bad.kind = DecodedPacket::Kind::kMalformed;
  bad.error = "bad";
  DecodedPacket position;
  position.kind = DecodedPacket::Kind::kIgnored;
  a.add(streamPacket(3));
  a.add(bad);
  a.add(position);
  EXPECT_EQ(a.stats().malformed, 1u);
  EXPECT_EQ(a.stats().ignored, 1u);
  EXPECT_EQ(a.stats().late_dropped, 0u);
  a.flush();
  EXPECT_EQ(scans.size(), 1u);
}

}  // namespace
}  // namespace rigcal::drivers
