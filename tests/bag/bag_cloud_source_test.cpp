// bag::BagCloudSource: malformed clouds dropped and counted; --rate 1 paces clouds by their log time.
#include <gtest/gtest.h>

#include <atomic>
#include <chrono>

#include "bag_pipeline_support.hpp"
#include "rigcal/bag/bag_cloud_source.hpp"
#include "rigcal/pipeline/sensor_driver.hpp"
#include "run_command.hpp"
#include "sanitizers.hpp"

namespace rigcal::test {
namespace {

using bag::test::SqliteBagWriter;

// A PointCloud2 message that does not decode is counted and dropped; the clouds around it still arrive.
TEST(BagCloudSource, AMalformedCloudIsDroppedAndTheOthersKept) {
  TempDir dir;
  {
    SqliteBagWriter bag(dir / "clouds.db3");
    const int id = bag.topic("/points", "sensor_msgs/msg/PointCloud2");
    for (int k = 0; k < 3; ++k) {
      Scan scan;
      scan.stamp_ns = 1'000'000'000 + k * 100'000'000;
      for (int i = 0; i < 5; ++i)
        scan.push_back({float(i + 1), 0.5f, 0.25f, 2.0f, std::uint16_t(i), scan.stamp_ns + i * 1000, 0});
      auto bytes = bag::test::pointCloud2(scan, "lidar");
      if (k == 1) bytes.resize(bytes.size() - 40);  // cut inside the point data
      bag.write(id, scan.stamp_ns, bytes);
    }
  }
  bag::BagCloudSource source(dir / "clouds.db3", "");
  std::vector<Scan> scans;
  while (auto c = source.next()) scans.push_back(std::move(c->scan));
  ASSERT_EQ(scans.size(), 2u);
  EXPECT_EQ(scans[0].stamp_ns, 1'000'000'000);
  EXPECT_EQ(scans[1].stamp_ns, 1'200'000'000);
  EXPECT_EQ(scans[1].size(), 5u);
  EXPECT_EQ(scans[1].offset_ns[4], 4000u) << "per-point times from t";
  EXPECT_EQ(source.stats().malformed, 1u);
  EXPECT_NE(source.warning().find("1 malformed messages dropped, last: " + (dir / "clouds.db3").string() +
                                  ": /points message at log time 1100000000"),
            std::string::npos)
      << source.warning();
}

// --rate 1 on a PointCloud2 topic: each cloud is handed on at its log time (offset from the first), as
// PacedSource paces a pcap's packets; --rate max does not wait.
TEST(BagCloudSource, RecordedRatePacesCloudsByTheirLogTime) {
  TempDir dir;
  {
    SqliteBagWriter bag(dir / "clouds.db3");
    const int id = bag.topic("/points", "sensor_msgs/msg/PointCloud2");
    for (int k = 0; k < 4; ++k) {
      Scan scan;
      scan.stamp_ns = 1'000'000'000 + k * 100'000'000;
      for (int i = 0; i < 5; ++i) scan.push_back({float(i + 1), 0.5f, 0.25f, 2.0f, std::uint16_t(i), scan.stamp_ns, 0});
      bag.write(id, scan.stamp_ns, bag::test::pointCloud2(scan, "lidar"));
    }
  }
  config::SensorConfig sensor;
  sensor.name = "lidar";
  sensor.model = pipeline::kPointCloud2Model;
  const auto run = [&](double rate) {
    pipeline::DriverInput input;
    input.bag = dir / "clouds.db3";
    input.rate = rate;
    const std::atomic<bool> stop{false};
    std::vector<std::pair<std::string, double>> got;
    const auto t0 = std::chrono::steady_clock::now();
    pipeline::SensorDriver driver(sensor, input, stop, [&](Scan&& scan) {
      got.emplace_back(scan.sensor_id, std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count());
    });
    driver.run();
    return got;
  };
  const auto paced = run(1.0);
  ASSERT_EQ(paced.size(), 4u);
  EXPECT_EQ(paced[0].first, "lidar");
  const auto fast = run(0.0);
  ASSERT_EQ(fast.size(), 4u);
  if (kWallClockAsserted) {
    EXPECT_GE(paced.back().second - paced.front().second, 0.29) << "3 gaps of 100 ms";
    EXPECT_LT(fast.back().second, 0.25);
  }
}

}  // namespace
}  // namespace rigcal::test
