// The simulated RS-Helios-16P beyond the point round trip (round_trip_test.cpp): its DIFOP packets
// (angles, port, cadence), the rig file that brings them to the decoder, and restamping for
// `rigcal replay --clock now`.
#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "rigcal/config/rig_config.hpp"
#include "rigcal/drivers/packet_restamper.hpp"
#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/drivers/robosense/robosense_packet.hpp"
#include "rigcal/sim/outputs.hpp"
#include "rigcal/sim/recording.hpp"
#include "sanitizers.hpp"
#include "test_data.hpp"

namespace rigcal::sim {
namespace {

namespace fs = std::filesystem;
namespace rs = drivers::robosense;

Scenario helios(double seconds, const char* layout) {
  return parseScenario(std::string("scenario: helios\nseed: 7\nrig:\n  mapping_lidar: h\n  sensors:\n"
                                   "    - {name: h, model: RS-Helios-16P, address: 192.168.1.200, port: 6699, "
                                   "extrinsic: {z: 1.8}}\nscene: {layout: ") +
                           layout + "}\ntrajectory: {segments: [{type: stop, duration: " + std::to_string(seconds) +
                           "}]}\n",
                       "helios");
}

void record(const Simulation& sim, const fs::path& dir, double seconds) {
  writeRigFiles(sim, dir);
  SimulationOptions o;
  o.threads = 2;
  o.build_scans = false;
  o.max_duration_ns = fromSeconds(seconds);
  writeRecording(sim, makeEncoders(sim), dir / "recording.pcap", o);
}

// A DIFOP goes to port 7788 before the first data packet and then once a second; it decodes to the
// simulated angles, which are the recorded unit's (the DIFOP in robosense/helios16p.pcap).
TEST(RobosenseSim, DifopCarriesTheSimulatedAnglesToItsOwnPortOnceASecond) {
  const double seconds = 2.1;  // an empty scene: only the packets' cost
  const Simulation sim(helios(seconds + 0.1, "empty"));
  const LidarModel& model = sim.model(0);
  rigcal::test::TempDir dir;
  record(sim, dir.path(), seconds);
  ASSERT_EQ(infoPort(sim.scenario().sensors[0], model), 7788);

  drivers::PcapSource source(dir / "recording.pcap");
  std::vector<TimeNs> difop_times;
  std::size_t msop = 0, msop_before_difop = 0;
  rs::DeviceInfo info;
  while (auto p = source.next()) {
    if (p->destination.port == 7788) {
      ASSERT_EQ(rs::parseDifop(p->payload, info), "");
      difop_times.push_back(p->receive_ns);
    } else {
      EXPECT_EQ(p->destination.port, 6699);
      rs::MsopView view;
      ASSERT_EQ(rs::parseMsop(p->payload, view), "");
      ++msop;
      if (difop_times.empty()) ++msop_before_difop;
    }
  }
  EXPECT_EQ(msop_before_difop, 0u) << "the decoder holds data until the first DIFOP";
  EXPECT_GT(msop, 1000u);
  ASSERT_EQ(difop_times.size(), 3u) << "one at the start, then one a second";
  for (std::size_t i = 1; i < difop_times.size(); ++i)
    EXPECT_NEAR(toSeconds(difop_times[i] - difop_times[i - 1]), 1.0, 0.001);

  EXPECT_EQ(info.rpm, 600);
  EXPECT_EQ(int(info.return_mode), int(rs::ReturnMode::kStrongest));
  std::vector<std::pair<std::int32_t, std::int32_t>> simulated, recorded;
  for (int l = 0; l < rs::kLasers; ++l) {
    const std::size_t beam = std::size_t(l);
    EXPECT_EQ(info.vertical[beam], std::lround(model.beams[beam].elevation_deg * 100)) << "laser " << l;
    EXPECT_EQ(info.horizontal[beam], std::lround(detail::helios16pHorizontalOffsetDeg(model, beam) * 100)) << "laser " << l;
    // The second firing of each laser (slot l + 16) has the same angles.
    EXPECT_EQ(model.beams[beam + 16].elevation_deg, model.beams[beam].elevation_deg);
    EXPECT_NEAR(detail::helios16pHorizontalOffsetDeg(model, beam + 16), detail::helios16pHorizontalOffsetDeg(model, beam), 1e-9);
    simulated.emplace_back(info.vertical[beam], info.horizontal[beam]);
  }

  RIGCAL_REQUIRE_DATA(real, "robosense/helios16p.pcap");
  drivers::PcapSource real_source(real);
  rs::DeviceInfo real_info;
  while (auto p = real_source.next())
    if (rs::isDifop(p->payload) && rs::parseDifop(p->payload, real_info).empty()) break;
  for (int l = 0; l < rs::kLasers; ++l) recorded.emplace_back(real_info.vertical[std::size_t(l)], real_info.horizontal[std::size_t(l)]);
  std::sort(simulated.begin(), simulated.end());
  std::sort(recorded.begin(), recorded.end());
  EXPECT_EQ(simulated, recorded) << "the recorded unit's calibration, lasers renumbered from the lowest";
}

// rig.yaml names the DIFOP port and no calibration file (the angles come in the DIFOP).
TEST(RobosenseSim, RigFileNamesTheInfoPortAndNoCalibration) {
  const Simulation sim(helios(0.2, "empty"));
  rigcal::test::TempDir dir;
  const auto written = writeRigFiles(sim, dir.path());
  EXPECT_EQ(written.size(), 1u) << "rig.yaml only";
  const config::RigConfig rig = config::loadRigConfig(dir / "rig.yaml");
  ASSERT_EQ(rig.sensors.size(), 1u);
  EXPECT_EQ(rig.sensors[0].model, "RS-Helios-16P");
  EXPECT_EQ(rig.sensors[0].source.port, 6699);
  EXPECT_EQ(rig.sensors[0].source.info_port, std::optional<std::uint16_t>(7788));
  EXPECT_TRUE(rig.sensors[0].calibration.empty());
}

// What `rigcal replay --clock now` does to each packet: the MSOP times move by the shift, the DIFOP
// stays as it is, and the decoder gives the same points, each later by exactly the shift.
TEST(RobosenseSim, RestampedCaptureDecodesWithEveryPointShifted) {
  const double seconds = RIGCAL_SANITIZED ? 0.1 : 0.3;
  const Simulation sim(helios(seconds + 0.1, "parking-lot"));
  rigcal::test::TempDir dir;
  record(sim, dir.path(), seconds);
  drivers::DecoderConfig config;
  config.model = "RS-Helios-16P";
  config.time_source = TimeSource::kSensorClock;
  const drivers::PacketRestamper restamper(config);
  auto original = drivers::makeDecoder(config), shifted = drivers::makeDecoder(config);
  constexpr std::int64_t kShiftUs = 123LL * 86'400'000'000LL + 4'567'891;
  drivers::PcapSource source(dir / "recording.pcap");
  drivers::DecodedPacket a, b;
  std::size_t points = 0, difops = 0;
  while (auto p = source.next()) {
    std::vector<std::uint8_t> payload(p->payload.begin(), p->payload.end());
    const bool restamped = restamper.restamp(payload, kShiftUs);
    EXPECT_EQ(restamped, !rs::isDifop(p->payload));
    difops += rs::isDifop(p->payload) ? 1 : 0;
    original->decode(*p, a);
    drivers::UdpPacket moved = *p;
    moved.payload = payload;
    shifted->decode(moved, b);
    ASSERT_EQ(int(a.kind), int(b.kind)) << b.error;
    ASSERT_EQ(a.points.size(), b.points.size());
    for (std::size_t i = 0; i < a.points.size(); ++i) {
      ASSERT_EQ(b.points[i].time_ns - a.points[i].time_ns, kShiftUs * 1000);
      ASSERT_EQ(b.points[i].x, a.points[i].x);
    }
    points += a.points.size();
  }
  EXPECT_EQ(difops, 1u);
  EXPECT_GT(points, 10'000u);
}

}  // namespace
}  // namespace rigcal::sim
