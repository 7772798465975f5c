// The Pipeline on simulator scenarios, fed in process: keyframes, stopped and lost frames, the mapping
// trajectory against the truth, pairing statistics against the truth, selection, determinism.
#include <gtest/gtest.h>

#include <algorithm>
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

using test::runInProcess;
using test::truthAt;

// Simulating is CPU-heavy: a segment in Release, a few seconds under the sanitizers.
constexpr double kParkingLotSeconds = RIGCAL_SANITIZED ? 3.0 : 14.0;

config::Parameters& testParameters(config::RigConfig& rig) {
  auto& p = rig.parameters;
  p.calibration_skip_keyframes = 2;
  p.dense_pointcloud_num_keyframes = 3;
  p.lidar_calibration_max_frames = 3;
  p.lidar_calibration_min_frames = 2;
  p.calibration_min_distance_between_frames = 3.0;
  return p;
}

// One simulated segment serves every check (simulating is the expensive part): one ctest entry.
struct ParkingLot {
  std::unique_ptr<sim::Simulation> sim;
  std::unique_ptr<rigcal::test::TempDir> dir;
  config::RigConfig rig;
  std::unique_ptr<test::RunResult> result;
};
ParkingLot* g = nullptr;

const MappingResult& mapping() { return g->result->mapping; }
std::size_t top() { return g->sim->scenario().sensorIndex("top"); }
/// The truth of the mapping lidar in the map frame (the first registered frame).
Pose truthInMap(TimeNs stamp) {
  const Pose W0 = truthAt(*g->sim, top(), mapping().trajectory.front().stamp_ns);
  return W0.inverse() * truthAt(*g->sim, top(), stamp);
}
double trueTime(TimeNs stamp) {  // seconds since the trajectory's start
  return toSeconds(stamp - g->sim->scenario().sensors[top()].clock_offset_ns - g->sim->startTime());
}

void checkEveryScanIsRegisteredInOrder() {
  const auto& t = mapping().trajectory;
  ASSERT_GE(t.size(), std::size_t(kParkingLotSeconds * 10 - 3));
  EXPECT_EQ(g->result->progress.registered, t.size());
  for (std::size_t i = 1; i < t.size(); ++i) EXPECT_GT(t[i].stamp_ns, t[i - 1].stamp_ns);
  for (const auto& q : g->result->stats.queues) EXPECT_EQ(q.dropped, 0u) << q.name;  // offline: lossless
  ASSERT_TRUE(mapping().map_cloud);
  EXPECT_GT(mapping().map_cloud->size(), 10000u);
  ASSERT_TRUE(mapping().dense_cloud);
  EXPECT_GT(mapping().dense_cloud->size(), 10000u);
}

void checkNoLostFrames() {
  for (const auto& f : mapping().trajectory) EXPECT_FALSE(f.lost) << f.sequence << ": " << f.lost_reason;
}

void checkKeyframesAreNewKeyframeMinDistanceApart() {
  const double d = g->rig.parameters.new_keyframe_min_distance;
  std::vector<MappingFrame> kfs;
  for (const auto& f : mapping().trajectory)
    if (f.kind == FrameKind::kKeyframe) kfs.push_back(f);
  ASSERT_GE(kfs.size(), RIGCAL_SANITIZED ? 1u : 10u);
  for (std::size_t i = 1; i < kfs.size(); ++i) {
    const double along = kfs[i].path_length - kfs[i - 1].path_length;
    const double truth = (truthInMap(kfs[i].stamp_ns).translation() - truthInMap(kfs[i - 1].stamp_ns).translation()).norm();
    // One keyframe per new_keyframe_min_distance of path: at most one frame's travel (< 0.2 m at 5 km/h) more.
    EXPECT_GE(along, d) << "keyframe " << kfs[i].keyframe_index;
    EXPECT_LT(along, d + 0.2) << "keyframe " << kfs[i].keyframe_index;
    EXPECT_NEAR(truth, along, 0.05) << "keyframe " << kfs[i].keyframe_index;
  }
}

void checkStoppedFramesDuringTheStopOnly() {
  int stopped_in_stop = 0;
  for (const auto& f : mapping().trajectory) {
    const double t = trueTime(f.stamp_ns);
    const double speed = g->sim->trajectory().speed(t);
    const bool is_stopped = f.kind == FrameKind::kStopped || f.kind == FrameKind::kStoppedKeyframe;
    if (is_stopped) {  // upstream's rule: ≤ new_frame_min_distance per frame, steadily (0.5 m/s at 10 Hz)
      EXPECT_LT(speed, 0.55) << "frame " << f.sequence << " at " << t << " s";
    }
    if (t > 0.3 && t < 1.9) {  // the scenario stands still for its first 2 s
      EXPECT_TRUE(is_stopped) << "frame " << f.sequence << " at " << t << " s is " << toString(f.kind);
      stopped_in_stop += is_stopped;
    }
  }
  EXPECT_GE(stopped_in_stop, 12);
  // The N-th stopped frame in a row is stored as a stopped keyframe.
  const auto stopped_kf = std::count_if(mapping().trajectory.begin(), mapping().trajectory.end(),
                                        [](const MappingFrame& f) { return f.kind == FrameKind::kStoppedKeyframe; });
  EXPECT_GE(stopped_kf, 1);
}

void checkTrajectoryWithin2cmAnd0p1DegreePer10m() {
  const auto& t = mapping().trajectory;
  double worst_m = 0, worst_deg = 0;
  int pairs = 0;
  const double span = RIGCAL_SANITIZED ? 2.0 : 10.0;
  for (std::size_t i = 0; i < t.size(); ++i) {
    for (std::size_t j = i + 1; j < t.size(); ++j) {
      if (t[j].path_length - t[i].path_length < span) continue;
      const Pose est = t[i].T_map_lidar.inverse() * t[j].T_map_lidar;
      const Pose truth = truthInMap(t[i].stamp_ns).inverse() * truthInMap(t[j].stamp_ns);
      const Pose err = truth.inverse() * est;
      worst_m = std::max(worst_m, err.translation().norm());
      worst_deg = std::max(worst_deg, rad2deg(rotationAngle(err)));
      ++pairs;
      break;
    }
  }
  std::cout << "relative error per " << span << " m over " << pairs << " pairs: worst " << worst_m * 100 << " cm, "
            << worst_deg << " deg\n";
  if (!RIGCAL_SANITIZED) {
    EXPECT_GE(pairs, 20);
  }
  EXPECT_LT(worst_m, 0.02);
  EXPECT_LT(worst_deg, 0.1);
}

void checkInterpolationStatisticsMatchTruth() {
  if (RIGCAL_SANITIZED) return;  // too short a drive under sanitizers
  int checked = 0;
  for (const auto& d : g->result->datasets) {
    for (const Pairing& p : d->candidates) {
      const MappingFrame& kf = d->trajectory.at(p.keyframe_frame);
      EXPECT_DOUBLE_EQ(p.stats.time_s, std::abs(toSeconds(p.scan_stamp_ns - kf.stamp_ns)));
      const Pose truth = truthInMap(p.scan_stamp_ns);
      EXPECT_LT((truth.translation() - p.T_map_mapping_at_scan.translation()).norm(), 0.03) << p.scan_sequence;
      EXPECT_LT(rad2deg(rotationAngleBetween(truth, p.T_map_mapping_at_scan)), 0.2) << p.scan_sequence;
      const double true_distance = (truth.translation() - truthInMap(kf.stamp_ns).translation()).norm();
      EXPECT_NEAR(p.stats.distance_m, true_distance, 0.01) << p.scan_sequence;
      const double true_angle = rad2deg(rotationAngleBetween(truthInMap(kf.stamp_ns), truth));
      EXPECT_NEAR(p.stats.angle_deg, true_angle, 0.1) << p.scan_sequence;
      // The lidar's speed (the base's, plus the turn's lever arm) by central difference of the truth.
      const TimeNs h = 50 * kNsPerMs;
      const double true_speed =
          (truthInMap(p.scan_stamp_ns + h).translation() - truthInMap(p.scan_stamp_ns - h).translation()).norm() /
          toSeconds(2 * h);
      EXPECT_NEAR(p.stats.speed, true_speed, 0.05) << p.scan_sequence;
      EXPECT_LT(p.stats.accel, 1.0) << p.scan_sequence;
      ++checked;
    }
  }
  EXPECT_GE(checked, 10);
}

void checkSelectionRespectsBudgetAndSpacing() {
  if (RIGCAL_SANITIZED) return;  // too short a drive under sanitizers
  const auto& p = g->rig.parameters;
  ASSERT_EQ(g->result->datasets.size(), 2u);
  for (const auto& d : g->result->datasets) {
    SCOPED_TRACE(d->calibration_sensor);
    EXPECT_TRUE(d->budget_full);
    EXPECT_EQ(int(d->frames.size()), p.lidar_calibration_max_frames);
    for (std::size_t i = 0; i < d->frames.size(); ++i) {
      const auto& f = d->frames[i];
      ASSERT_TRUE(f.raw && f.deskewed);
      EXPECT_GE(int(f.deskewed->size()), p.min_calibration_pointcloud_size);
      EXPECT_GE(f.information, p.calibration_min_pca_eigenvalue);
      EXPECT_TRUE(f.pairing.accepted);
      if (i > 0) {  // most informative first
        EXPECT_LE(f.information, d->frames[i - 1].information);
      }
      for (std::size_t j = 0; j < i; ++j) {
        const double a = d->trajectory[f.pairing.keyframe_frame].path_length;
        const double b = d->trajectory[d->frames[j].pairing.keyframe_frame].path_length;
        EXPECT_GE(std::abs(a - b), p.calibration_min_distance_between_frames);
      }
    }
    // Every other candidate is accounted for with a reason.
    EXPECT_EQ(d->rejected.size() + d->frames.size(), d->candidates.size());
    for (const auto& r : d->rejected) EXPECT_FALSE(r.reason.empty());
    // The dense windows: stored mapping frames with clouds, in sequence order.
    ASSERT_FALSE(d->mapping_clouds.empty());
    for (std::size_t i = 1; i < d->mapping_clouds.size(); ++i)
      EXPECT_LT(d->mapping_clouds[i - 1].frame.sequence, d->mapping_clouds[i].frame.sequence);
    for (const auto& m : d->mapping_clouds) EXPECT_GT(m.cloud->size(), 1000u);
    EXPECT_TRUE(d->T_mapping_calib_guess.isApprox(g->rig.initial_T_base_sensor.at("top").inverse() *
                                                  g->rig.initial_T_base_sensor.at(d->calibration_sensor)));
  }
  EXPECT_TRUE(g->result->shortfalls.empty());
  for (const auto& l : g->result->progress.lidars) EXPECT_TRUE(l.handed_over) << l.sensor;
}


TEST(PipelineSim, ParkingLotSegment) {
  ParkingLot run;
  run.sim = std::make_unique<sim::Simulation>(sim::loadScenario("parking-lot"));
  run.dir = std::make_unique<rigcal::test::TempDir>();
  run.rig = test::rigFor(*run.sim, run.dir->path());
  testParameters(run.rig);
  run.result = std::make_unique<test::RunResult>(runInProcess(*run.sim, run.rig, kParkingLotSeconds));
  std::cout << run.result->stats.table() << run.result->progress.line() << '\n';
  g = &run;
  {
    SCOPED_TRACE("EveryScanIsRegisteredInOrder");
    checkEveryScanIsRegisteredInOrder();
  }
  {
    SCOPED_TRACE("NoLostFrames");
    checkNoLostFrames();
  }
  {
    SCOPED_TRACE("KeyframesAreNewKeyframeMinDistanceApart");
    checkKeyframesAreNewKeyframeMinDistanceApart();
  }
  {
    SCOPED_TRACE("StoppedFramesDuringTheStopOnly");
    checkStoppedFramesDuringTheStopOnly();
  }
  {
    SCOPED_TRACE("TrajectoryWithin2cmAnd0p1DegreePer10m");
    checkTrajectoryWithin2cmAnd0p1DegreePer10m();
  }
  {
    SCOPED_TRACE("InterpolationStatisticsMatchTruth");
    checkInterpolationStatisticsMatchTruth();
  }
  {
    SCOPED_TRACE("SelectionRespectsBudgetAndSpacing");
    checkSelectionRespectsBudgetAndSpacing();
  }
  g = nullptr;
}


/// The `lost` scenario shortened: a 1.5 s mapping-lidar dropout at 4.5 s and the 0.35 s jerk at 8 s.
TEST(PipelineSim, LostFramesAtTheDropoutAndTheJerkOnly) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << "11 s of simulation and mapping: Release only (the same code runs in the other tests)";
  sim::Scenario sc = sim::loadScenario("lost");
  using K = sim::TrajectorySegment::Kind;
  const double kmh = 1.0 / 3.6;
  sc.trajectory.segments = {{K::kStop, 1.0, 0.0, 0.0},     {K::kAccelerate, 2.0, 5 * kmh, 0.0},
                            {K::kCruise, 5.0, {}, 0.0},     {K::kJerk, 0.35, 18 * kmh, 0.0},
                            {K::kAccelerate, 2.5, 5 * kmh, 0.0}, {K::kCruise, 1.0, {}, 0.0}};
  const double outage_from = 4.5, outage_to = 6.0, jerk_from = 8.0, jerk_to = 8.35;
  sc.sensors[sc.sensorIndex("top")].outages = {{outage_from, outage_to}};
  const double seconds = 11.5;
  sim::Simulation sim(sc);
  rigcal::test::TempDir dir;
  config::RigConfig rig = test::rigFor(sim, dir.path());
  const test::RunResult r = runInProcess(sim, rig, seconds);
  std::cout << r.progress.line() << '\n';

  const std::size_t top = sc.sensorIndex("top");
  int lost_after_dropout = 0, lost_at_jerk = 0;
  bool first_after_dropout = true;
  for (const auto& f : r.mapping.trajectory) {
    const double t = toSeconds(f.stamp_ns - sc.sensors[top].clock_offset_ns - sim.startTime());
    if (t > outage_to && first_after_dropout) {
      first_after_dropout = false;
      EXPECT_TRUE(f.lost) << "first frame after the dropout, at " << t << " s";
    }
    if (!f.lost) continue;
    std::cout << "lost frame " << f.sequence << " at " << t << " s: " << f.lost_reason << '\n';
    // The frames right after the dropout may fail to register until the map restarts from a full sweep.
    if (t > outage_to && t <= outage_to + 0.5) ++lost_after_dropout;
    else if (t >= jerk_from && t <= jerk_to + 0.5) ++lost_at_jerk;
    else ADD_FAILURE() << "lost frame at " << t << " s, away from the dropout and the jerk: " << f.lost_reason;
  }
  EXPECT_GE(lost_after_dropout, 1);
  if (seconds > jerk_to + 0.5) {
    EXPECT_GE(lost_at_jerk, 1);
  }
  EXPECT_EQ(r.progress.lost_frames, std::uint64_t(lost_after_dropout + lost_at_jerk));
}

/// Recorded scans of the first seconds of parking-lot (mapping lidar and front_left), fed twice.
struct Recorded : sim::SimulationSink {
  std::vector<Scan> scans;
  void onScan(sim::SimulatedScan&& s) override {
    if (s.scan.sensor_id != "front_right") scans.push_back(std::move(s.scan));
  }
};

test::RunResult replay(const config::RigConfig& rig, const std::vector<Scan>& scans, PipelineOptions o,
                       double* push_seconds = nullptr) {
  test::RunResult r;
  std::mutex m;
  Pipeline pipeline(rig, o, [&](std::shared_ptr<const CalibrationDataset> d) {
    std::lock_guard lock(m);
    r.datasets.push_back(std::move(d));
  });
  const auto t0 = std::chrono::steady_clock::now();
  for (const Scan& s : scans) pipeline.push(s);
  if (push_seconds) *push_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - t0).count();
  pipeline.finish();
  r.mapping = pipeline.mapping(/*with_dense_cloud=*/true);
  r.progress = pipeline.progress();
  r.stats = pipeline.stats();
  r.shortfalls = pipeline.shortfalls();
  return r;
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
  EXPECT_LT(push_seconds, 0.5 * double(recorded_.scans.size()) / 20.0);
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
  for (const Scan& s : recorded_.scans) {
    std::this_thread::sleep_until(start + std::chrono::nanoseconds(s.stamp_ns - first));
    if (writers[s.sensor_id]->publish(s)) ++published[s.sensor_id];
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
  for (const auto& q : st.queues) EXPECT_EQ(q.dropped, 0u) << q.name;
  EXPECT_GE(p.registered, expected - 2);  // the first partial sweeps may be too small to register
}

}  // namespace
}  // namespace rigcal::pipeline
