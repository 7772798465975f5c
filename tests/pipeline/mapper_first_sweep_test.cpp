// The map is never seeded with an incomplete sweep: a capture that starts mid-rotation (the HDL-32E
// capture of ../shared/data: its first sweep holds 34 of 85 ms) used to seed the map with it, and the
// next two full sweeps, half outside that map, failed their fitness check and were lost.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <cmath>
#include <vector>

#include "rigcal/config/rig_config.hpp"
#include "rigcal/pipeline/mapper.hpp"
#include "rigcal/pipeline/sensor_driver.hpp"
#include "sanitizers.hpp"
#include "test_data.hpp"

namespace rigcal::pipeline {
namespace {

std::vector<Scan> decodeCapture(const std::filesystem::path& pcap, const std::string& model) {
  config::SensorConfig sensor;
  sensor.name = "top";
  sensor.model = model;
  sensor.source.port = 2368;
  std::vector<Scan> scans;
  std::atomic<bool> stop{false};
  SensorDriver driver(sensor, DriverInput{pcap, 0.0}, stop, [&](Scan&& s) { scans.push_back(std::move(s)); });
  driver.run();
  return scans;
}

TEST(MapperFirstSweep, APartialFirstSweepDoesNotSeedTheMap) {
  RIGCAL_REQUIRE_DATA(pcap, "velodyne/hdl32e_example.pcap");
  const std::vector<Scan> scans = decodeCapture(pcap, "HDL-32E");
  ASSERT_GE(scans.size(), 5u);
  Mapper mapper(config::Parameters{});
  std::vector<MapperOutput> out;
  for (const Scan& s : scans) out.push_back(mapper.process(s));

  // The partial first sweep is skipped, saying why; the first whole sweep seeds the map.
  EXPECT_FALSE(out[0].registered);
  EXPECT_NE(out[0].skipped_reason.find("incomplete sweep cannot seed the map"), std::string::npos)
      << out[0].skipped_reason;
  ASSERT_TRUE(out[1].registered) << out[1].skipped_reason;
  EXPECT_EQ(out[1].registration.status, "first");
  EXPECT_EQ(out[1].frame.sequence, scans[1].sequence);
  // The whole sweeps after it register against a whole map: none lost (they were, seeded by the part).
  for (std::size_t i = 2; i <= 4; ++i) {
    ASSERT_TRUE(out[i].registered) << i;
    EXPECT_TRUE(out[i].registration.ok) << "scan " << i << ": " << out[i].registration.status << ", inliers "
                                        << out[i].registration.inlier_ratio;
    EXPECT_FALSE(out[i].frame.lost) << "scan " << i << ": " << out[i].frame.lost_reason;
  }
}

// The pipeline publishes a pose before the frame's dense cloud and local-map feed (deferPostPoseWork).
// Finishing each frame after process(), or leaving it to the next process(), gives the frames, clouds and
// map of the undeferred mapper, bit for bit.
TEST(MapperDeferred, PostPoseWorkDoneLaterGivesTheSameFramesAndMap) {
  RIGCAL_REQUIRE_DATA(pcap, "velodyne/hdl32e_example.pcap");
  const std::vector<Scan> scans = decodeCapture(pcap, "HDL-32E");
  ASSERT_GE(scans.size(), 5u);
  Mapper plain(config::Parameters{});
  Mapper deferred(config::Parameters{});
  deferred.deferPostPoseWork(true);
  std::size_t clouds = 0, keyframes = 0;
  // Two mappers on ~70k-point scans: fewer under the sanitizers, still enough for two keyframes.
  const std::size_t count = RIGCAL_SANITIZED ? std::min<std::size_t>(scans.size(), 12) : scans.size();
  for (std::size_t i = 0; i < count; ++i) {
    const MapperOutput a = plain.process(scans[i]);
    MapperOutput b = deferred.process(scans[i]);
    EXPECT_EQ(b.cloud, nullptr) << "deferred: no dense cloud before finishFrame()";
    // Every other frame, and every other keyframe (the only ones with a dense cloud), is finished at once;
    // the others are left to the next process(), which must feed the map itself.
    const bool finish_now = a.frame.isKeyframe() ? keyframes++ % 2 == 0 : i % 2 == 0;
    if (finish_now) deferred.finishFrame(b);
    ASSERT_EQ(a.registered, b.registered) << i;
    EXPECT_EQ(a.frame.kind, b.frame.kind) << i;
    EXPECT_EQ(a.frame.T_map_lidar.matrix(), b.frame.T_map_lidar.matrix()) << i;
    if (finish_now) {
      ASSERT_EQ(a.cloud == nullptr, b.cloud == nullptr) << i;
      if (a.cloud) {
        EXPECT_EQ(a.cloud->x, b.cloud->x) << i;
        ++clouds;
      }
    }
  }
  EXPECT_GE(keyframes, 2u);
  EXPECT_GE(clouds, 1u);
  EXPECT_EQ(plain.mapCloud()->x, deferred.mapCloud()->x);
  EXPECT_EQ(plain.localMapPoints(), deferred.localMapPoints());
}

/// A ring of wall points at 5 m over the azimuth range [from_deg, to_deg), 16 rings high.
Scan arc(double from_deg, double to_deg, std::uint64_t sequence) {
  Scan s;
  s.sensor_id = "top";
  s.sequence = sequence;
  s.stamp_ns = TimeNs(sequence) * 100'000'000;
  for (double a = from_deg; a < to_deg; a += 0.2)
    for (int r = 0; r < 16; ++r) {
      const double rad = a * M_PI / 180.0;
      const auto offset = TimeNs((a - from_deg) / 360.0 * 1e8);
      s.push_back(Point{float(5 * std::cos(rad)), float(5 * std::sin(rad)), float(-1 + 0.15 * r), 0.0f,
                        std::uint16_t(r), s.stamp_ns + offset, 0});
    }
  return s;
}

TEST(MapperFirstSweep, ALimitedFieldOfViewLosesOneSweepNeverMore) {
  config::Parameters p;
  p.min_mapping_pointcloud_size = 1000;
  Mapper mapper(p);
  // A sensor that only ever sees 180°: its first sweep is taken for a partial one, the next one seeds.
  const MapperOutput first = mapper.process(arc(-90, 90, 0));
  EXPECT_FALSE(first.registered);
  const MapperOutput second = mapper.process(arc(-90, 90, 1));
  ASSERT_TRUE(second.registered) << second.skipped_reason;
  EXPECT_EQ(second.registration.status, "first");

  // A whole first sweep seeds the map at once.
  Mapper whole(p);
  const MapperOutput w = whole.process(arc(-180, 180, 0));
  ASSERT_TRUE(w.registered) << w.skipped_reason;
  EXPECT_EQ(w.registration.status, "first");
}

}  // namespace
}  // namespace rigcal::pipeline
