#include <gtest/gtest.h>

#include <cmath>

#include "rigcal/drivers/scan_assembler.hpp"

namespace rigcal::drivers {
namespace {

// A packet of `n` points at azimuths start, start+step, ... (mod 360), `dt` ns apart.
DecodedPacket packet(TimeNs t0, float start, float step, int n, TimeNs dt = 1000) {
  DecodedPacket p;
  p.packet_time_ns = t0;
  for (int i = 0; i < n; ++i) {
    p.points.push_back(Point{1, 0, 0, 0, 0, t0 + i * dt, 0});
    p.azimuth_deg.push_back(std::fmod(start + step * float(i) + 360.f, 360.f));
  }
  return p;
}

TEST(ScanAssembler, CutsAtTheCutAngleInsideAPacket) {
  std::vector<Scan> scans;
  ScanAssembler a("s", AssemblerConfig{90.0}, [&](Scan&& s) { scans.push_back(std::move(s)); });
  // Two turns of 360 points each, one degree apart, packets of 36 points starting at 0°.
  TimeNs t = 0;
  for (int k = 0; k < 20; ++k, t += 36'000) a.add(packet(t, float(k % 10) * 36.f, 1.f, 36));
  a.flush();
  ASSERT_EQ(scans.size(), 3u);
  EXPECT_EQ(scans[0].size(), 90u);   // 0..89°
  EXPECT_EQ(scans[1].size(), 360u);  // 90°..89° of the next turn
  EXPECT_EQ(scans[2].size(), 270u);  // the partial turn flushed at the end
  EXPECT_EQ(scans[1].stamp_ns, 90'000);
  EXPECT_EQ(scans[1].offset_ns.back(), 359'000u);
  EXPECT_EQ(scans[1].sequence, 1u);
}

TEST(ScanAssembler, LimitedFovGapDoesNotCutUnlessTheCutIsInside) {
  std::vector<Scan> scans;
  ScanAssembler a("s", AssemblerConfig{0.0}, [&](Scan&& s) { scans.push_back(std::move(s)); });
  // FOV 270° → 90°: points only there; the cut at 0° lies inside the FOV.
  TimeNs t = 0;
  for (int turn = 0; turn < 2; ++turn)
    for (int k = 0; k < 5; ++k, t += 36'000) a.add(packet(t, 270.f + 36.f * float(k), 1.f, 36));
  a.flush();
  ASSERT_EQ(scans.size(), 3u);
  EXPECT_EQ(scans[1].size(), 180u);
}

TEST(ScanAssembler, SmallBackwardJitterIsNotATurn) {
  std::vector<Scan> scans;
  ScanAssembler a("s", AssemblerConfig{0.0}, [&](Scan&& s) { scans.push_back(std::move(s)); });
  DecodedPacket p = packet(0, 10.f, 1.f, 10);
  p.azimuth_deg[5] = 13.5f;  // slightly behind its predecessor
  a.add(p);
  a.flush();
  ASSERT_EQ(scans.size(), 1u);
}

TEST(ScanAssembler, FrameIdChangeCutsAndLossIsCounted) {
  std::vector<Scan> scans;
  ScanAssembler a("s", AssemblerConfig{}, [&](Scan&& s) { scans.push_back(std::move(s)); });
  for (int k = 0; k < 6; ++k) {
    DecodedPacket p = packet(k * 1000, 0.f, 0.f, 4);
    p.frame_id = k / 3;
    p.lost_before = k == 4 ? 2 : 0;
    a.add(p);
  }
  DecodedPacket bad;
  bad.kind = DecodedPacket::Kind::kMalformed;
  bad.error = "packet 7: bad magic";
  a.add(bad);
  a.flush();
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_EQ(scans[0].missing_packets, 0u);
  EXPECT_EQ(scans[1].missing_packets, 2u);
  EXPECT_EQ(a.stats().malformed, 1u);
  EXPECT_EQ(a.stats().lost_packets, 2u);
  EXPECT_EQ(a.stats().last_error, "packet 7: bad magic");
}

TEST(ScanAssembler, LongSilenceEndsTheSweep) {
  std::vector<Scan> scans;
  ScanAssembler a("s", AssemblerConfig{0.0}, [&](Scan&& s) { scans.push_back(std::move(s)); });
  a.add(packet(0, 10.f, 1.f, 10));
  a.add(packet(kNsPerSec, 30.f, 1.f, 10));
  a.flush();
  ASSERT_EQ(scans.size(), 2u);
}

}  // namespace
}  // namespace rigcal::drivers
