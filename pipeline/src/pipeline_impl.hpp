#pragma once
// Pipeline::Impl, shared by pipeline.cpp (construction, finish, the public API), pipeline_sources.cpp
// (ingest: driver threads, ring readers, push) and pipeline_stages.cpp (the deskew, mapper, pairing and
// selector threads). Private to the pipeline library.

#include "rigcal/pipeline/pipeline.hpp"

#include "rigcal/pipeline/bounded_queue.hpp"  // first: moodycamel's semaphore needs its queue header

#include <algorithm>
#include <chrono>
#include <condition_variable>
#include <deque>
#include <map>
#include <mutex>
#include <stdexcept>

#include "pairing_lane.hpp"
#include "ring_input_tally.hpp"
#include "selection_lane.hpp"
#include "trajectory_buffer.hpp"
#include "rigcal/pipeline/bounded_queue.hpp"
#include "rigcal/pipeline/deskew.hpp"
#include "rigcal/pipeline/mapper.hpp"
#include "rigcal/pipeline/sensor_driver.hpp"
#include "rigcal/pipeline/stage_thread.hpp"
#include "rigcal/registration/voxel_grid.hpp"
#include "rigcal/shm/scan_ring_reader.hpp"

namespace rigcal::pipeline::detail {

inline std::int64_t steadyNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

constexpr std::chrono::microseconds kPollTimeout{100'000};  // stage threads re-check abort this often
constexpr std::size_t kLosslessCapacity = 1 << 16;          // small messages that must never be dropped
constexpr TimeNs kCalibrationLeadNs = kNsPerSec;            // offline pcap: calibration lidars run ahead by ≤ 1 s
constexpr std::int64_t kRealtimeHoldNs = 1'000'000'000;     // real time: longest wait for the trajectory
/// Offline the sources outrun the mapper, so the scan queues sit full: at 32 scans of a 128-beam lidar
/// (~5 MB each) the input queues alone held ~340 MB, and the deskew stage's held calibration scans grow
/// with the mapper's backlog (issue #18). A few scans keep every stage busy. Real time keeps the option's
/// capacity: there the queue is what absorbs a slow stage before scans are dropped.
constexpr std::size_t kOfflineScanQueueCapacity = 4;

inline std::size_t scanQueueCapacity(const PipelineOptions& o) {
  const std::size_t wanted = std::max<std::size_t>(2, o.queue_capacity);
  return o.mode == PipelineMode::kOffline ? std::min(wanted, kOfflineScanQueueCapacity) : wanted;
}

struct ScanItem {
  std::shared_ptr<Scan> scan;
  int sensor = -1;  // 0 = mapping lidar, 1.. = calibration lidars
  std::int64_t t0_ns = 0;
  bool end = false;
};

struct PoseItem {
  TimeNs stamp = 0;
  Pose pose = Pose::Identity();
  bool end = false;
};

struct FrameItem {
  MapperOutput out;
  bool end = false;
};

struct CalItem {
  int lane = 0;
  DeskewedScan scan;
  bool end = false;
};

struct CandItem {
  CandidateMessage c;
  bool end = false;
};

/// A stage's latency histogram and counter, written by its thread and read by stats() at any time.
struct StageRecord {
  explicit StageRecord(std::string n) : name(std::move(n)) {}
  std::string name;
  mutable std::mutex mutex;
  LatencyHistogram latency;
  std::uint64_t processed = 0;
  void record(std::int64_t t0_ns) {
    const std::int64_t now = steadyNs();
    std::lock_guard lock(mutex);
    latency.record(std::max<std::int64_t>(0, now - t0_ns));
    ++processed;
  }
};

struct LaneCounters {
  std::atomic<std::uint64_t> scans{0}, candidates{0}, accepted{0}, selected{0};
  std::atomic<std::uint64_t> lost_packets{0};  // Scan::missing_packets summed: drivers and rings alike
  std::atomic<std::uint64_t> malformed_packets{0};  // its driver's count so far (in-process, or its ring's writer)
  std::atomic<bool> handed_over{false};
};

}  // namespace rigcal::pipeline::detail

namespace rigcal::pipeline {

using namespace detail;  // the Impl's own vocabulary (this header is private to the library)

struct Pipeline::Impl {
  config::RigConfig rig;
  config::Parameters params;
  PipelineOptions options;
  DatasetCallback on_dataset;
  bool realtime = false;
  std::vector<std::string> sensors;  // 0 = mapping lidar, then the calibration lidars
  Pose T_base_mapping = Pose::Identity();
  std::vector<Pose> T_mapping_calib;  // per lane
  std::chrono::steady_clock::time_point started = std::chrono::steady_clock::now();
  std::atomic<double> wall_seconds{0.0};

  // Queues, in data-flow order.
  BoundedQueue<ScanItem> q_in;      // sources → deskew
  BoundedQueue<ScanItem> q_map;     // deskew → mapper
  BoundedQueue<PoseItem> q_pose;    // mapper → deskew (the trajectory for calibration deskew)
  BoundedQueue<FrameItem> q_frames; // mapper → pairing
  BoundedQueue<CalItem> q_cal;      // deskew → pairing
  BoundedQueue<CandItem> q_cand;    // pairing → selector
  moodycamel::LightweightSemaphore wake_deskew{0, 1}, wake_pairing{0, 1};

  StageRecord rec_ingest{"ingest"}, rec_deskew{"deskew"}, rec_mapper{"mapper"}, rec_pairing{"pairing"},
      rec_selector{"selector"};

  // Progress.
  std::atomic<std::uint64_t> skipped{0};
  std::atomic<std::uint64_t> mapping_scans{0}, registered{0}, stored{0}, keyframes{0}, stopped{0}, lost{0},
      unknown_sensor_scans{0}, mapping_lost_packets{0}, mapping_malformed_packets{0};
  std::atomic<bool> mapping_done{false};
  std::vector<std::unique_ptr<LaneCounters>> lanes;

  // The mapper and what it stored (read by mapping() and the selector).
  mutable std::mutex mapper_mutex;
  Mapper mapper;
  std::vector<MappingFrame> trajectory;
  mutable std::mutex store_mutex;
  std::vector<MappingFrame> stored_frames;
  // Each stored frame's cloud: a keyframe's, nullptr for the others and once released.
  std::vector<std::shared_ptr<const Scan>> stored_clouds;
  std::vector<std::size_t> stored_keyframes;

  // Results of the selector.
  mutable std::mutex result_mutex;
  std::vector<Shortfall> shortfalls;

  // Threads.
  std::atomic<bool> abort{false};
  std::atomic<bool> source_stop{false};
  std::vector<StageThread> stages;  // deskew, mapper, pairing, selector
  std::vector<StageThread> sources;  // appended by run() under sources_mutex (stats() reads them)
  mutable std::mutex sources_mutex;
  std::vector<std::unique_ptr<SensorDriver>> drivers;
  std::vector<int> driver_sensor;  // sensor index of each driver
  std::vector<std::unique_ptr<shm::ScanRingReader>> readers;
  std::vector<std::unique_ptr<RingInputTally>> ring_tallies;  // per reader: what its writers counted
  std::atomic<int> sources_running{0};
  std::atomic<int> live_writers{0};          // rings whose writer delivered and is not known gone
  std::atomic<bool> writers_gone{false};     // every ring writer seen is gone: the shm input ends
  std::mutex finish_mutex;
  std::atomic<bool> finished{false};
  std::atomic<std::uint64_t> ring_overruns{0};

  // Offline pcap: calibration drivers wait for the mapping driver (bounded memory, no deadlock).
  std::mutex lead_mutex;
  std::condition_variable lead_cv;
  TimeNs mapping_ingested_stamp = INT64_MIN;
  bool mapping_source_done = false;

  Impl(const config::RigConfig& r, const PipelineOptions& o, DatasetCallback cb)
      : rig(r),
        params(r.parameters),
        options(o),
        on_dataset(std::move(cb)),
        realtime(o.mode == PipelineMode::kRealtime),
        q_in(scanQueueCapacity(o)),
        q_map(scanQueueCapacity(o)),
        q_pose(kLosslessCapacity),
        q_frames(kLosslessCapacity),
        q_cal(scanQueueCapacity(o)),
        q_cand(kLosslessCapacity),
        mapper(r.parameters, o.mode == PipelineMode::kOffline) {
    mapper.deferPostPoseWork(true);  // the mapper stage publishes the pose before the frame's other work
    if (rig.roles.mapping_lidar.empty()) throw std::runtime_error(rig.file.string() + ": no mapping_lidar role");
    sensors.push_back(rig.roles.mapping_lidar);
    for (const auto& c : rig.roles.calibration_lidars) sensors.push_back(c);
    const auto extrinsic = [&](const std::string& name) {
      const auto it = rig.initial_T_base_sensor.find(name);
      if (it == rig.initial_T_base_sensor.end())
        throw std::runtime_error(rig.file.string() + ": no initial extrinsic for sensor '" + name + "'");
      return it->second;
    };
    T_base_mapping = extrinsic(sensors[0]);
    for (std::size_t i = 1; i < sensors.size(); ++i) {
      T_mapping_calib.push_back(T_base_mapping.inverse() * extrinsic(sensors[i]));
      lanes.push_back(std::make_unique<LaneCounters>());
    }
  }

  int sensorIndex(const std::string& name) const;
  void ingest(Scan&& scan, int sensor, std::int64_t t0_ns);
  void endOfInput();
  DeskewedScan deskewCalibration(const ScanItem& item, const TrajectoryBuffer& traj) const;
  void deskewStage();
  void mapperStage();
  void pairingStage();
  std::shared_ptr<const Scan> storedCloud(std::size_t i) const;
  /// Drops the store's reference to clouds before `bound`, keeping the dense window of the last keyframe.
  void releaseBefore(std::size_t bound);
  /// Hands `d` over: the callback gets the pipeline's only reference (moved), so that whoever it gives it to
  /// owns the dataset's clouds alone and can free them while the selector waits on it (offline).
  void deliver(std::shared_ptr<const CalibrationDataset> d, std::size_t lane);
  void selectorStage();
  void waitForMappingLead(TimeNs stamp);
  void mappingIngested(TimeNs stamp, bool done);
  void setUpSources();
  void startSources();
  void readRing(std::size_t r);
  void startStages();
  // Stops the driver threads / ring readers and waits for them (caller holds finish_mutex).
  void stopSources();
  void finish();
  void shutdown();
};

}  // namespace rigcal::pipeline
