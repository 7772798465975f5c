// Vendor encoders judged by rigcal's own decoders: simulate → recording.pcap → makeDecoder +
// ScanAssembler → the simulated points back within each model's quantisation.
#include <gtest/gtest.h>
#include <yaml-cpp/yaml.h>

#include <map>
#include <set>

#include "round_trip_util.hpp"
#include "sanitizers.hpp"
#include "sim_test_util.hpp"
#include "test_data.hpp"

namespace rigcal::sim {
namespace {

using test::poseFrom;

using rigcal::test::TempDir;
using rigcal::test::fileContents;

namespace fs = std::filesystem;

// Short drives keep the tests fast; sanitizer builds shorter still.
constexpr double kDriveSeconds = RIGCAL_SANITIZED ? 0.15 : 0.6;

struct Generated {
  RecordingResult result;
  std::unique_ptr<test::FiringRecorder> recorder;
};

Generated generate(const Simulation& sim, const fs::path& dir, TimeNs duration_ns, int threads = 2) {
  writeRigFiles(sim, dir);
  Generated g;
  g.recorder = std::make_unique<test::FiringRecorder>(sim.sensorCount());
  SimulationOptions o;
  o.threads = threads;
  o.build_scans = false;
  o.max_duration_ns = duration_ns;
  g.result = writeRecording(sim, makeEncoders(sim), dir / "recording.pcap", o, g.recorder.get());
  return g;
}

struct ModelCase {
  const char* model;
  // What the decoded azimuth may be off by: Velodyne 0.02° (block azimuths rounded to 0.01°, the
  // step between them too, and the interpolated point azimuth rounded again); Hesai 0.01° (block
  // azimuth rounded, the channel's offset exact); Ouster none (the column fixes the angle).
  double azimuth_resolution_deg;
  // Mean signed azimuth error allowed. RS-Helios-16P: its decoders truncate a slot's share of the block's
  // azimuth step to 0.01° (rs_driver, nebula), a bias of about −0.005° on a round trip.
  double azimuth_bias_deg = 0.002;
};

// Names the case in test listings (the default prints the struct's bytes, pointers included).
void PrintTo(const ModelCase& c, std::ostream* os) { *os << c.model; }

class RoundTrip : public ::testing::TestWithParam<ModelCase> {};

TEST_P(RoundTrip, DecodersGiveBackTheSimulatedPointsWithinQuantisation) {
  const ModelCase c = GetParam();
  const Simulation sim(test::movingLidar(c.model, 8.0, 20.0, 0.02, 0.02, kDriveSeconds + 0.2));
  TempDir dir;
  const Generated g = generate(sim, dir.path(), fromSeconds(kDriveSeconds));
  ASSERT_GT(g.result.datagrams, 0u);
  const test::SensorRoundTrip r =
      test::decodeAndCompare(sim, 0, dir.path(), dir / "recording.pcap", g.recorder->sensors[0], c.azimuth_resolution_deg);
  EXPECT_EQ(r.malformed, 0u) << r.last_error;
  EXPECT_EQ(r.lost, 0u);
  EXPECT_GE(r.scans, 2u);
  EXPECT_GT(r.decoded, 1000u);
  EXPECT_EQ(r.matched, r.decoded) << "every decoded point is a simulated return of that beam and firing";
  EXPECT_EQ(r.matched, r.expected) << "every simulated return in the decoded span came back";
  EXPECT_LE(r.max_excess_m, 0.0) << "largest error " << r.max_error_m << " m";
  EXPECT_LE(r.max_time_error_ns, 1'000) << "packet timestamps resolve at least 1 µs";
  EXPECT_LT(std::abs(r.mean_azimuth_error_deg), c.azimuth_bias_deg) << "no azimuth bias";
  std::cout << c.model << ": " << r.decoded << " points in " << r.scans << " sweeps, largest error "
            << r.max_error_m * 1000 << " mm, largest time error " << r.max_time_error_ns
            << " ns, mean azimuth error " << r.mean_azimuth_error_deg << "°\n";
}

INSTANTIATE_TEST_SUITE_P(Models, RoundTrip,
                         ::testing::Values(ModelCase{"VLP-16", 0.02}, ModelCase{"OS1-64", 0.001},
                                           ModelCase{"VLP-32C", 0.02}, ModelCase{"VLS-128", 0.02},
                                           ModelCase{"OS1-128", 0.001}, ModelCase{"PandarXT32", 0.01},
                                           ModelCase{"Pandar64", 0.01},
                                           // As Velodyne's: block azimuths and the step between them rounded,
                                           // the slot's share of the step truncated to 0.01°.
                                           ModelCase{"RS-Helios-16P", 0.02, 0.006}),
                         [](const ::testing::TestParamInfo<ModelCase>& param_info) {
                           std::string n = param_info.param.model;
                           std::erase(n, '-');
                           return n;
                         });

TEST(RoundTripCapture, SameSeedGivesAByteIdenticalCaptureWhateverTheThreads) {
  const Simulation sim(test::movingLidar("VLP-16", 8.0, 0.0, 0.02, 0.02, 0.5));
  TempDir a, b;
  generate(sim, a.path(), fromSeconds(0.2), 2);
  generate(sim, b.path(), fromSeconds(0.2), 1);
  const std::string pa = fileContents(a / "recording.pcap"), pb = fileContents(b / "recording.pcap");
  EXPECT_GT(pa.size(), 100'000u);
  EXPECT_TRUE(pa == pb) << "same seed, same bytes";
}

// A sensor outage: the sensor sends nothing for 0.1 s. The decoders see the packets as lost (Velodyne
// by time, Ouster by measurement id, Hesai by udp_sequence), nothing is malformed, and every point
// that does come back is the simulated one.
TEST(RoundTripCapture, AnOutageIsSeenAsLostPacketsByEveryVendor) {
  constexpr double kOutageFrom = RIGCAL_SANITIZED ? 0.05 : 0.2;
  for (const char* model : {"VLP-16", "OS1-64", "PandarXT32", "Pandar64", "RS-Helios-16P"}) {
    const Scenario sc = parseScenario(std::string("scenario: outage\nseed: 4\nrig:\n  mapping_lidar: l\n  sensors:\n"
                                                  "    - {name: l, model: ") + model +
                                          ", address: 10.0.0.2, port: 2368, extrinsic: {z: 1.9}, "
                                          "outages: [{from: " + std::to_string(kOutageFrom) + ", to: " +
                                          std::to_string(kOutageFrom + 0.1) + "}]}\n"
                                          "scene: {layout: parking-lot}\ntrajectory:\n"
                                          "  start: {x: -20, y: -6, speed_kmh: 6}\n  segments: [{type: cruise, duration: 0.5}]\n",
                                      "outage");
    const Simulation sim(sc);
    TempDir dir;
    const Generated g = generate(sim, dir.path(), fromSeconds(kOutageFrom + 0.25));
    const test::SensorRoundTrip r =
        test::decodeAndCompare(sim, 0, dir.path(), dir / "recording.pcap", g.recorder->sensors[0], 0.02);
    EXPECT_EQ(r.malformed, 0u) << model << ": " << r.last_error;
    EXPECT_GT(r.lost, 0u) << model;
    EXPECT_GT(r.decoded, 1000u) << model;
    EXPECT_EQ(r.matched, r.decoded) << model;
    EXPECT_LE(r.max_excess_m, 0.0) << model;
  }
}

// The Ouster LEGACY profile (scenario `udp_profile: LEGACY`): the metadata says so and the decoder reads
// the packets back just as exactly.
TEST(RoundTripCapture, OusterLegacyProfile) {
  Scenario sc = test::movingLidar("OS1-64", 8.0, 10.0, 0.02, 0.02, kDriveSeconds + 0.2);
  sc.sensors[0].ouster_legacy = true;
  const Simulation sim(sc);
  TempDir dir;
  const Generated g = generate(sim, dir.path(), fromSeconds(kDriveSeconds));
  const test::SensorRoundTrip r =
      test::decodeAndCompare(sim, 0, dir.path(), dir / "recording.pcap", g.recorder->sensors[0], 0.001);
  EXPECT_EQ(r.malformed, 0u) << r.last_error;
  EXPECT_EQ(r.lost, 0u);
  EXPECT_GT(r.decoded, 1000u);
  EXPECT_EQ(r.matched, r.decoded);
  EXPECT_EQ(r.matched, r.expected);
  EXPECT_LE(r.max_excess_m, 0.0) << "largest error " << r.max_error_m << " m";
  drivers::PcapSource source(dir / "recording.pcap");
  const auto p = source.next();
  ASSERT_TRUE(p);
  EXPECT_EQ(p->payload.size(), 16u * (16 + 64 * 12 + 4)) << "LEGACY: no packet header or footer";
}

// A NIC sees a packet after the sensor sent it, and the sensor sends it after the last firing it
// carries: every datagram's capture stamp (true clock) is later than each of its points' times (sensor
// clock − clock offset), and not by much more than the packet's own duration.
TEST(RoundTripCapture, CaptureStampsFollowTheLastFiringOfEachPacket) {
  const Simulation sim(loadScenario("street"));
  TempDir dir;
  generate(sim, dir.path(), fromSeconds(RIGCAL_SANITIZED ? 0.1 : 0.25));
  std::map<std::pair<std::uint32_t, std::uint16_t>, std::size_t> sensor_of;
  std::vector<std::unique_ptr<drivers::PacketDecoder>> decoders;
  for (std::size_t i = 0; i < sim.sensorCount(); ++i) {
    const SensorSpec& s = sim.scenario().sensors[i];
    sensor_of[{ipv4FromText(s.address), s.port}] = i;
    drivers::DecoderConfig config;
    config.model = s.model;
    const std::string file = vendorFile(s, sim.model(i)).first;
    if (sim.model(i).vendor == LidarVendor::kOuster) config.metadata = dir / file;
    else config.calibration = dir / file;
    decoders.push_back(drivers::makeDecoder(config));
  }
  drivers::PcapSource source(dir / "recording.pcap");
  drivers::DecodedPacket decoded;
  std::vector<std::size_t> checked(sim.sensorCount(), 0);
  TimeNs worst_lag = 0;
  while (auto p = source.next()) {
    const std::size_t i = sensor_of.at({p->source.address, p->destination.port});
    decoders[i]->decode(*p, decoded);
    if (decoded.kind != drivers::DecodedPacket::Kind::kData || decoded.points.empty()) continue;
    TimeNs last = decoded.points.front().time_ns;
    for (const auto& pt : decoded.points) last = std::max(last, pt.time_ns);
    const TimeNs last_true = last - sim.scenario().sensors[i].clock_offset_ns;
    EXPECT_GT(p->receive_ns, last_true) << sim.scenario().sensors[i].name;
    worst_lag = std::max(worst_lag, p->receive_ns - last_true);
    ++checked[i];
  }
  for (std::size_t i = 0; i < sim.sensorCount(); ++i) EXPECT_GT(checked[i], 10u) << sim.scenario().sensors[i].name;
  EXPECT_LT(worst_lag, 5 * kNsPerMs) << "sent soon after its last firing";
}

// The street preset (VLS-128, VLP-16, OS1-64, PandarXT32 with clock offsets and scan phases): every
// datagram comes from the address and port of exactly one sensor, in that sensor's packet size, and
// each sensor's decoder gives back its simulated points; truth.yaml composes.
TEST(RoundTripCapture, EverySensorOfAPresetFromItsOwnSourceAndDecodable) {
  const Simulation sim(loadScenario("street"));
  TempDir dir;
  const Generated g = generate(sim, dir.path(), fromSeconds(RIGCAL_SANITIZED ? 0.15 : 0.35));
  const std::map<std::string, std::size_t> packet_size = {
      {"VLS-128", 1206}, {"VLP-16", 1206}, {"VLP-32C", 1206}, {"OS1-64", 12544}, {"OS1-128", 24832}, {"PandarXT32", 1080}};
  std::map<std::pair<std::uint32_t, std::uint16_t>, std::size_t> sensor_of;
  for (std::size_t i = 0; i < sim.sensorCount(); ++i) {
    const SensorSpec& s = sim.scenario().sensors[i];
    sensor_of[{ipv4FromText(s.address), s.port}] = i;
  }
  ASSERT_EQ(sensor_of.size(), sim.sensorCount()) << "the preset gives each sensor its own address and port";
  std::vector<std::size_t> datagrams(sim.sensorCount(), 0);
  drivers::PcapSource source(dir / "recording.pcap");
  while (auto p = source.next()) {
    const auto it = sensor_of.find({p->source.address, p->destination.port});
    ASSERT_NE(it, sensor_of.end()) << "a datagram from no sensor's address and port";
    const SensorSpec& s = sim.scenario().sensors[it->second];
    EXPECT_EQ(p->payload.size(), packet_size.at(s.model)) << s.name;
    ++datagrams[it->second];
  }
  EXPECT_EQ(source.stats().fragments_dropped, 0u);
  for (std::size_t i = 0; i < sim.sensorCount(); ++i) {
    const SensorSpec& s = sim.scenario().sensors[i];
    EXPECT_GT(datagrams[i], 10u) << s.name;
    const double az = sim.model(i).vendor == LidarVendor::kVelodyne ? 0.02 : 0.01;
    const test::SensorRoundTrip r =
        test::decodeAndCompare(sim, i, dir.path(), dir / "recording.pcap", g.recorder->sensors[i], az);
    EXPECT_EQ(r.malformed, 0u) << s.name << ": " << r.last_error;
    EXPECT_GT(r.decoded, 1000u) << s.name;
    EXPECT_EQ(r.matched, r.decoded) << s.name;
    EXPECT_EQ(r.matched, r.expected) << s.name;
    EXPECT_LE(r.max_excess_m, 0.0) << s.name << ": largest error " << r.max_error_m << " m";
  }

  writeTruthYaml(sim, dir / "truth.yaml");
  const YAML::Node t = YAML::LoadFile((dir / "truth.yaml").string());
  const Pose T_base_mapping = poseFrom(t["sensors"][sim.scenario().mapping_lidar]["T_base_sensor"]);
  for (const std::string& c : sim.scenario().calibration_lidars) {
    const Pose T_base_calib = poseFrom(t["sensors"][c]["T_base_sensor"]);
    const Pose T_mapping_calib = poseFrom(t["T_mapping_calib"][c]);
    EXPECT_LT((T_mapping_calib.matrix() - (T_base_mapping.inverse() * T_base_calib).matrix()).norm(), 1e-8) << c;
  }
}

}  // namespace
}  // namespace rigcal::sim
