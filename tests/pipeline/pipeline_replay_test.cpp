// The Pipeline on recorded simulator scans fed to it again: determinism, real-time input that never
// blocks, shortfall reports, the NDT mapper, shared-memory rings as input, and live UDP end to end.
#include <gtest/gtest.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cmath>
#include <map>
#include <thread>

#include <unistd.h>

#include "rigcal/shm/scan_ring_writer.hpp"
#include "rigcal/sim/recording.hpp"
#include "rigcal/sim/scenario.hpp"
#include "run_command.hpp"
#include "sim_pipeline_util.hpp"
#include "sanitizers.hpp"

namespace rigcal::pipeline {
namespace {

/// Recorded scans of the first seconds of parking-lot (mapping lidar and front_left), fed twice.
struct Recorded : sim::SimulationSink {
  std::vector<Scan> scans;
  void onScan(sim::SimulatedScan&& s) override {
    if (s.scan.sensor_id != "front_right") scans.push_back(std::move(s.scan));
  }
};

test::RunResult replay(const config::RigConfig& rig, const std::vector<Scan>& scans, PipelineOptions o,
                       double* push_seconds = nullptr) {
  return test::runPipeline(rig, o, [&](Pipeline& pipeline) {
    const auto t0 = std::chrono::steady_clock::now();
    for (const Scan& s : scans) pipeline.push(s);
    if (push_seconds) *push_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  });
}

class Replayed : public ::testing::Test {
 protected:
  void SetUp() override {
    sim_ = std::make_unique<sim::Simulation>(sim::loadScenario("parking-lot"));
    rig_ = test::rigFor(*sim_, dir_.path());
    rig_.roles.calibration_lidars = {"front_left"};
    auto& p = rig_.parameters;
    p.calibration_skip_keyframes = 0;
    p.dense_pointcloud_num_keyframes = 1;
    p.lidar_calibration_max_frames = 2;
    p.calibration_min_distance_between_frames = 1.0;
    sim::SimulationOptions so;
    so.max_duration_ns = fromSeconds(RIGCAL_SANITIZED ? 2.0 : 6.5);
    sim_->run(recorded_, so);
  }
  rigcal::test::TempDir dir_;
  std::unique_ptr<sim::Simulation> sim_;
  config::RigConfig rig_;
  Recorded recorded_;
};

TEST_F(Replayed, TwoOfflineRunsGiveIdenticalFrames) {
  const test::RunResult a = replay(rig_, recorded_.scans, {});
  const test::RunResult b = replay(rig_, recorded_.scans, {});
  ASSERT_EQ(a.mapping.trajectory.size(), b.mapping.trajectory.size());
  ASSERT_GT(a.mapping.trajectory.size(), RIGCAL_SANITIZED ? 10u : 20u);
  for (std::size_t i = 0; i < a.mapping.trajectory.size(); ++i) {
    const auto& fa = a.mapping.trajectory[i];
    const auto& fb = b.mapping.trajectory[i];
    EXPECT_EQ(fa.sequence, fb.sequence);
    EXPECT_EQ(fa.kind, fb.kind) << fa.sequence;
    EXPECT_EQ(fa.lost, fb.lost) << fa.sequence;
    EXPECT_TRUE(fa.T_map_lidar.matrix() == fb.T_map_lidar.matrix()) << fa.sequence;
  }
  ASSERT_EQ(a.datasets.size(), b.datasets.size());
  for (std::size_t d = 0; d < a.datasets.size(); ++d) {
    const auto& da = *a.datasets[d];
    const auto& db = *b.datasets[d];
    ASSERT_EQ(da.candidates.size(), db.candidates.size());
    for (std::size_t i = 0; i < da.candidates.size(); ++i) {
      EXPECT_EQ(da.candidates[i].scan_sequence, db.candidates[i].scan_sequence);
      EXPECT_EQ(da.candidates[i].keyframe_frame, db.candidates[i].keyframe_frame);
      EXPECT_EQ(da.candidates[i].accepted, db.candidates[i].accepted);
    }
    ASSERT_EQ(da.frames.size(), db.frames.size());
    for (std::size_t i = 0; i < da.frames.size(); ++i)
      EXPECT_EQ(da.frames[i].pairing.scan_sequence, db.frames[i].pairing.scan_sequence);
    EXPECT_EQ(da.mapping_clouds.size(), db.mapping_clouds.size());
  }
  EXPECT_EQ(a.shortfalls.size(), b.shortfalls.size());
}

// Offline, each sensor's driver reads the capture on its own thread: a calibration lidar's scans may reach
// the pipeline seconds after the mapping lidar's of the same time (only running ahead is bounded). Its
// scans must still be deskewed through the trajectory at their own times, as when they come in time:
// the trajectory had been trimmed to the last 2 s, so a late scan was deskewed by extrapolating the oldest
// poses left, and the same recording selected other frames from run to run.
TEST_F(Replayed, ACalibrationLidarBehindTheMappingLidarIsDeskewedAsIfOnTime) {
  // Sanitized builds replay 2 s only: too short for a calibration dataset (and for the old 2 s buffer to
  // have lost any pose).
  if (RIGCAL_SANITIZED) { GTEST_SKIP() << "a 2 s replay has no calibration dataset"; }
  std::vector<Scan> late;  // every mapping scan first, then every calibration scan
  for (const Scan& s : recorded_.scans)
    if (s.sensor_id != "front_left") late.push_back(s);
  for (const Scan& s : recorded_.scans)
    if (s.sensor_id == "front_left") late.push_back(s);
  const test::RunResult on_time = replay(rig_, recorded_.scans, {});
  const test::RunResult behind = replay(rig_, late, {});
  ASSERT_EQ(on_time.datasets.size(), 1u);
  ASSERT_EQ(behind.datasets.size(), 1u);
  const auto& a = *on_time.datasets[0];
  const auto& b = *behind.datasets[0];
  ASSERT_EQ(a.frames.size(), b.frames.size());
  ASSERT_GT(a.frames.size(), 0u);
  std::size_t long_before_the_end = 0;  // frames the old 2 s buffer no longer covered when they came
  for (std::size_t i = 0; i < a.frames.size(); ++i) {
    EXPECT_EQ(a.frames[i].pairing.scan_sequence, b.frames[i].pairing.scan_sequence);
    if (a.frames[i].deskewed->stamp_ns + 2 * kNsPerSec < on_time.mapping.trajectory.back().stamp_ns) ++long_before_the_end;
    const Scan& da = *a.frames[i].deskewed;
    const Scan& db = *b.frames[i].deskewed;
    ASSERT_EQ(da.size(), db.size());
    for (std::size_t j = 0; j < da.size(); ++j) {
      ASSERT_EQ(da.x[j], db.x[j]) << "frame " << i << " point " << j;
      ASSERT_EQ(da.y[j], db.y[j]) << "frame " << i << " point " << j;
      ASSERT_EQ(da.z[j], db.z[j]) << "frame " << i << " point " << j;
    }
    EXPECT_EQ(a.frames[i].information, b.frames[i].information);
  }
  EXPECT_GT(long_before_the_end, 0u);
}

TEST_F(Replayed, RealtimeNeverBlocksTheInputAndCountsDrops) {
  PipelineOptions o;
  o.mode = PipelineMode::kRealtime;
  o.queue_capacity = 2;
  double push_seconds = 0;
  const test::RunResult r = replay(rig_, recorded_.scans, o, &push_seconds);
  std::uint64_t dropped = 0;
  for (const auto& q : r.stats.queues) dropped += q.dropped;
  std::cout << r.stats.table();
  // Pushing every scan at once cannot wait for the mapper: the oldest work is dropped and counted.
  EXPECT_GT(dropped, 0u);
  if (rigcal::test::kWallClockAsserted) { EXPECT_LT(push_seconds, 0.5 * double(recorded_.scans.size()) / 20.0); }
  EXPECT_LT(r.progress.registered, r.progress.mapping_scans);
  EXPECT_GT(r.progress.registered, 0u);
}

TEST_F(Replayed, ShortfallSaysWhatIsMissing) {
  rig_.parameters.lidar_calibration_min_frames = 40;
  rig_.parameters.lidar_calibration_max_frames = 50;
  const test::RunResult r = replay(rig_, recorded_.scans, {});
  EXPECT_TRUE(r.datasets.empty());
  ASSERT_EQ(r.shortfalls.size(), 1u);
  EXPECT_EQ(r.shortfalls[0].sensor, "front_left");
  EXPECT_EQ(r.shortfalls[0].required, 40);
  EXPECT_NE(r.shortfalls[0].message.find("of 40 frames for front_left"), std::string::npos) << r.shortfalls[0].message;
  // The stats serialise as JSON with every stage.
  const std::string json = r.stats.json();
  for (const char* stage : {"ingest", "deskew", "mapper", "pairing", "selector"})
    EXPECT_NE(json.find(std::string("\"") + stage + "\""), std::string::npos) << stage;
}



/// mapping_registrator: ndt maps the same drive: no lost frame, every frame registered, and the poses
/// stay near GICP's.
TEST_F(Replayed, NdtMapperAgreesWithGicp) {
  const test::RunResult gicp = replay(rig_, recorded_.scans, {});
  rig_.parameters.mapping_registrator = "ndt";
  rig_.parameters.mapper_resolution = 2.0;  // as config/rigs/ouster-hesai-robot.yaml; upstream's 5 m is coarse
  const test::RunResult ndt = replay(rig_, recorded_.scans, {});
  ASSERT_EQ(ndt.mapping.trajectory.size(), gicp.mapping.trajectory.size());
  double worst = 0;
  for (std::size_t i = 0; i < ndt.mapping.trajectory.size(); ++i) {
    const auto& f = ndt.mapping.trajectory[i];
    EXPECT_FALSE(f.lost) << f.sequence << ": " << f.lost_reason;
    worst = std::max(worst, (f.T_map_lidar.translation() - gicp.mapping.trajectory[i].T_map_lidar.translation()).norm());
  }
  std::cout << "NDT vs GICP: worst " << worst * 100 << " cm\n";
  // Measured 5.0 cm with 2 m cells (11 cm with upstream's 5 m): NDT is the coarser mapper here.
  EXPECT_LT(worst, 0.08);
}

/// Input (c): the scans go through real shared-memory rings (as `rigcal driver` processes write them),
/// published at 1x their recorded timing; the pipeline's ring readers end when the writers close.
TEST_F(Replayed, ReadsTheDriversSharedMemoryRings) {
  const std::string prefix = "rigcal.pipetest." + std::to_string(::getpid()) + ".";
  std::map<std::string, std::unique_ptr<shm::ScanRingWriter>> writers;
  std::map<std::string, std::uint64_t> published;
  for (const std::string name : {"top", "front_left"}) {
    shm::WriterOptions w;
    w.sensor = name;
    w.name_prefix = prefix;
    w.slot_count = 16;
    for (const Scan& s : recorded_.scans)
      if (s.sensor_id == name) w.max_points = std::max<std::uint32_t>(w.max_points, std::uint32_t(s.size()));
    writers[name] = std::make_unique<shm::ScanRingWriter>(w);
  }
  PipelineOptions o;
  o.input = InputKind::kShm;
  o.mode = PipelineMode::kRealtime;
  o.shm_prefix = prefix;
  Pipeline pipeline(rig_, o);
  std::atomic<bool> stop{false};
  std::thread runner([&] { pipeline.run(stop); });

  const TimeNs first = recorded_.scans.front().stamp_ns;
  const auto start = std::chrono::steady_clock::now();
  // Every 4th front_left scan says its driver lost 3 packets: the consumer counts them per sensor.
  std::uint64_t injected_loss = 0, front_left_count = 0;
  for (const Scan& s : recorded_.scans) {
    std::this_thread::sleep_until(start + std::chrono::nanoseconds(s.stamp_ns - first));
    Scan sent = s;
    if (s.sensor_id == "front_left" && front_left_count++ % 4 == 0) sent.missing_packets = 3;
    if (writers[s.sensor_id]->publish(sent)) {
      ++published[s.sensor_id];
      injected_loss += sent.missing_packets;
    }
  }
  for (auto& [name, w] : writers) w->close();
  runner.join();  // ends by itself: every writer is gone

  const PipelineProgress p = pipeline.progress();
  const PipelineStats st = pipeline.stats();
  std::cout << st.table() << p.line() << '\n';
  ASSERT_GT(published["top"], RIGCAL_SANITIZED ? 10u : 20u);
  // Every published scan arrived, or was lost to a ring overrun and counted.
  EXPECT_EQ(p.mapping_scans + p.lidars.at(0).scans + st.input_dropped_scans, published["top"] + published["front_left"]);
  EXPECT_GE(p.mapping_scans, published["top"] * 9 / 10);
  EXPECT_GT(p.registered, 0u);
  std::uint64_t dropped = 0;
  for (const auto& q : st.queues) dropped += q.dropped;
  // Real time: what the mapper did not get was dropped and counted, never lost silently.
  // (A partial first sweep is skipped by the mapper, and counted too.)
  EXPECT_EQ(p.registered + p.skipped + dropped >= p.mapping_scans, true)
      << p.registered << " + " << p.skipped << " + " << dropped;
  EXPECT_LE(p.skipped, 1u);
  // Packet loss the drivers saw reaches the consumer's progress line, per sensor.
  EXPECT_EQ(p.mapping_lost_packets, 0u);
  EXPECT_GT(p.lidars.at(0).lost_packets, 0u);
  EXPECT_LE(p.lidars.at(0).lost_packets, injected_loss);
  if (st.input_dropped_scans == 0) {
    EXPECT_EQ(p.lidars.at(0).lost_packets, injected_loss);
  }
  EXPECT_NE(p.line().find(" (lost " + std::to_string(p.lidars.at(0).lost_packets) + " pkts)"), std::string::npos)
      << p.line();
}


/// End to end in real time: a simulated parking-lot recording (real wire formats) replayed over loopback
/// UDP at 1x by `rigcal replay`, received by the pipeline's driver threads (the code path of
/// `rigcal driver`), all on cores 0-1: no scan may be dropped.
TEST(PipelineEndToEnd, ParkingLotOverLoopbackUdpAt1xDropsNoScan) {
  const double seconds = RIGCAL_SANITIZED ? 3.0 : 6.0;
  sim::Simulation sim(sim::loadScenario("parking-lot"));
  rigcal::test::TempDir dir;
  config::RigConfig rig = test::rigFor(sim, dir.path());
  sim::SimulationOptions so;
  so.max_duration_ns = fromSeconds(seconds);
  sim::writeRecording(sim, sim::makeEncoders(sim), dir / "recording.pcap", so);

  // Loopback: the packets come from 127.0.0.1 (no source filter), on ports shifted away from other tests.
  const int offset = 20000 + int(::getpid() % 20000);
  for (auto& sensor : rig.sensors) {
    sensor.source.address.reset();
    sensor.source.port = std::uint16_t(sensor.source.port + offset);
  }
  PipelineOptions o;
  o.input = InputKind::kLive;
  o.mode = PipelineMode::kRealtime;
  o.cores = {0, 1};
  Pipeline pipeline(rig, o);
  std::atomic<bool> stop{false};
  std::thread runner([&] { pipeline.run(stop); });
  const auto replay = rigcal::test::runRigcal({"replay", (dir / "recording.pcap").string(), "--to", "127.0.0.1",
                                               "--rate", "1", "--port-offset", std::to_string(offset)});
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // the last sweeps end on a timeout
  stop = true;
  runner.join();
  ASSERT_EQ(replay.exit_code, 0) << replay.out << replay.err;

  const PipelineProgress p = pipeline.progress();
  const PipelineStats st = pipeline.stats();
  std::cout << st.table() << p.line() << '\n';
  const auto expected = std::uint64_t(seconds * 10) - 2;  // 10 Hz; partial first/last sweeps aside
  EXPECT_GE(p.mapping_scans, expected);
  for (const auto& l : p.lidars) EXPECT_GE(l.scans, expected) << l.sensor;
  // Keeping up with 1x real time is speed: asserted in the optimised build only (under ASan the pairing
  // stage's per-candidate frame information fell behind and a realtime queue dropped 6 scans).
  // Every scan that reached the mapper registers, but the first partial sweeps, which may be too small. In the
  // optimised build that is every scan of the drive; under ASan beside a busy machine the realtime queue before
  // deskew dropped 8 and the mapper got 24 (all registered): how many arrive is speed, not behaviour.
  std::uint64_t reached_mapper = expected;
  if (rigcal::test::kWallClockAsserted) {
    for (const auto& q : st.queues) EXPECT_EQ(q.dropped, 0u) << q.name;
  } else {
    for (const auto& s : st.stages)
      if (s.name == "mapper") reached_mapper = std::min<std::uint64_t>(expected, s.processed);
  }
  EXPECT_GE(p.registered + 2, reached_mapper);
}

}  // namespace
}  // namespace rigcal::pipeline
