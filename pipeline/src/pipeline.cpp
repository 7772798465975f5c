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
#include "selection_lane.hpp"
#include "trajectory_buffer.hpp"
#include "rigcal/pipeline/bounded_queue.hpp"
#include "rigcal/pipeline/deskew.hpp"
#include "rigcal/pipeline/mapper.hpp"
#include "rigcal/pipeline/sensor_driver.hpp"
#include "rigcal/pipeline/stage_thread.hpp"
#include "rigcal/registration/voxel_grid.hpp"
#include "rigcal/shm/scan_ring_reader.hpp"

namespace rigcal::pipeline {

namespace {

std::int64_t steadyNs() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(std::chrono::steady_clock::now().time_since_epoch())
      .count();
}

constexpr std::chrono::microseconds kPollTimeout{100'000};  // stage threads re-check abort this often
constexpr std::size_t kLosslessCapacity = 1 << 16;          // small messages that must never be dropped
constexpr TimeNs kCalibrationLeadNs = kNsPerSec;            // offline pcap: calibration lidars run ahead by ≤ 1 s
constexpr std::int64_t kRealtimeHoldNs = 1'000'000'000;     // real time: longest wait for the trajectory

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
  std::atomic<bool> handed_over{false};
};

TimeNs scanEnd(const Scan& s) {
  std::uint32_t m = 0;
  for (std::uint32_t o : s.offset_ns) m = std::max(m, o);
  return s.stamp_ns + TimeNs(m);
}

}  // namespace

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
  std::atomic<std::uint64_t> mapping_scans{0}, registered{0}, stored{0}, keyframes{0}, stopped{0}, lost{0},
      unknown_sensor_scans{0};
  std::atomic<bool> mapping_done{false};
  std::vector<std::unique_ptr<LaneCounters>> lanes;

  // The mapper and what it stored (read by mapping() and the selector).
  mutable std::mutex mapper_mutex;
  Mapper mapper;
  std::vector<MappingFrame> trajectory;
  mutable std::mutex store_mutex;
  std::vector<MappingFrame> stored_frames;
  std::vector<std::shared_ptr<const Scan>> stored_clouds;  // nullptr once released
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
  std::atomic<int> sources_running{0};
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
        q_in(std::max<std::size_t>(2, o.queue_capacity)),
        q_map(std::max<std::size_t>(2, o.queue_capacity)),
        q_pose(kLosslessCapacity),
        q_frames(kLosslessCapacity),
        q_cal(std::max<std::size_t>(2, o.queue_capacity)),
        q_cand(kLosslessCapacity),
        mapper(r.parameters, o.mode == PipelineMode::kOffline) {
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

  int sensorIndex(const std::string& name) const {
    for (std::size_t i = 0; i < sensors.size(); ++i)
      if (sensors[i] == name) return int(i);
    return -1;
  }

  // ---- ingest -------------------------------------------------------------------------------------------

  void ingest(Scan&& scan, int sensor, std::int64_t t0_ns) {
    if (sensor < 0) {
      unknown_sensor_scans.fetch_add(1, std::memory_order_relaxed);
      return;
    }
    if (sensor == 0) mapping_scans.fetch_add(1, std::memory_order_relaxed);
    else lanes[std::size_t(sensor - 1)]->scans.fetch_add(1, std::memory_order_relaxed);
    ScanItem item{std::make_shared<Scan>(std::move(scan)), sensor, t0_ns, false};
    if (realtime) q_in.pushDropOldest(std::move(item));
    else if (!q_in.push(std::move(item))) return;
    rec_ingest.record(t0_ns);
    wake_deskew.signal();
  }

  void endOfInput() {
    q_in.push(ScanItem{nullptr, -1, steadyNs(), true});
    wake_deskew.signal();
  }

  // ---- deskew -------------------------------------------------------------------------------------------

  DeskewedScan deskewCalibration(const ScanItem& item, const TrajectoryBuffer& traj) const {
    auto out = std::make_shared<Scan>(*item.scan);
    const Pose& T_mc = T_mapping_calib[std::size_t(item.sensor - 1)];
    if (!traj.empty()) {
      // The calibration lidar's motion: the mapping trajectory seen through the extrinsic guess.
      const Pose T_ref_map = (traj.at(out->stamp_ns) * T_mc).inverse();
      deskew(*out, [&](TimeNs t) { return T_ref_map * traj.at(t) * T_mc; });
    }
    return DeskewedScan{item.scan, std::move(out), item.t0_ns};
  }

  void deskewStage() {
    TrajectoryBuffer traj;
    bool traj_ended = false, input_ended = false;
    std::deque<ScanItem> held;  // calibration scans waiting for the trajectory to cover them
    while (!abort.load()) {
      bool progress = false;
      while (auto p = q_pose.tryPop()) {
        progress = true;
        if (p->end) traj_ended = true;
        else traj.add(p->stamp, p->pose);
      }
      while (!input_ended) {
        auto s = q_in.tryPop();
        if (!s) break;
        progress = true;
        if (s->end) {
          input_ended = true;
          q_map.push(std::move(*s));
        } else if (s->sensor == 0) {
          cropRange(*s->scan, params.mapping_min_range, params.mapping_max_range);
          const std::int64_t t0 = s->t0_ns;
          if (realtime) q_map.pushDropOldest(std::move(*s));
          else q_map.push(std::move(*s));
          rec_deskew.record(t0);
        } else {
          held.push_back(std::move(*s));
        }
      }
      while (!held.empty()) {
        const ScanItem& h = held.front();
        const bool covered = traj_ended || (!traj.empty() && traj.last() >= scanEnd(*h.scan));
        if (!covered && !(realtime && steadyNs() - h.t0_ns > kRealtimeHoldNs)) break;
        CalItem c{h.sensor - 1, deskewCalibration(h, traj), false};
        const std::int64_t t0 = h.t0_ns;
        held.pop_front();
        if (realtime) q_cal.pushDropOldest(std::move(c));
        else q_cal.push(std::move(c));
        rec_deskew.record(t0);
        wake_pairing.signal();
        progress = true;
      }
      if (!held.empty()) traj.trimBefore(held.front().scan->stamp_ns - kNsPerSec);
      else if (!traj.empty()) traj.trimBefore(traj.last() - 2 * kNsPerSec);
      if (input_ended && traj_ended && held.empty()) {
        q_cal.push(CalItem{0, {}, true});
        wake_pairing.signal();
        return;
      }
      if (!progress) wake_deskew.wait(kPollTimeout.count());
    }
  }

  // ---- mapper -------------------------------------------------------------------------------------------

  void mapperStage() {
    while (!abort.load()) {
      auto item = q_map.pop(kPollTimeout);
      if (!item) continue;
      if (item->end) {
        mapping_done.store(mapper.done());
        q_pose.push(PoseItem{0, Pose::Identity(), true});
        wake_deskew.signal();
        q_frames.push(FrameItem{{}, true});
        wake_pairing.signal();
        return;
      }
      MapperOutput out;
      {
        std::lock_guard lock(mapper_mutex);
        out = mapper.process(*item->scan);
        if (out.registered) trajectory.push_back(out.frame);
      }
      item->scan.reset();
      if (!out.registered) {
        mapping_done.store(mapper.done());
        continue;
      }
      registered.fetch_add(1);
      const MappingFrame& f = out.frame;
      if (f.stored()) {
        stored.fetch_add(1);
        std::lock_guard lock(store_mutex);
        if (f.isKeyframe()) stored_keyframes.push_back(stored_frames.size());
        stored_frames.push_back(f);
        stored_clouds.push_back(out.cloud);
      }
      if (f.isKeyframe()) keyframes.fetch_add(1);
      if (f.kind == FrameKind::kStopped || f.kind == FrameKind::kStoppedKeyframe) stopped.fetch_add(1);
      if (f.lost) lost.fetch_add(1);
      rec_mapper.record(item->t0_ns);
      q_pose.push(PoseItem{f.stamp_ns, f.T_map_lidar, false});
      wake_deskew.signal();
      q_frames.push(FrameItem{std::move(out), false});
      wake_pairing.signal();
    }
  }

  // ---- pairing ------------------------------------------------------------------------------------------

  void pairingStage() {
    std::vector<PairingLane> pairing;
    for (std::size_t i = 0; i < T_mapping_calib.size(); ++i) pairing.emplace_back(int(i), params, T_mapping_calib[i], realtime);
    std::vector<MappingFrame> frames;
    std::vector<std::size_t> kfs;
    std::vector<int> lost_kfs;
    TimeNs latest = INT64_MIN;
    bool mapping_ended = false, cal_ended = false;
    std::vector<CandidateMessage> out;
    while (!abort.load()) {
      bool progress = false;
      while (auto f = q_frames.tryPop()) {
        progress = true;
        if (f->end) {
          mapping_ended = true;
          continue;
        }
        const MappingFrame& m = f->out.frame;
        latest = std::max(latest, m.stamp_ns);
        if (!m.stored()) continue;
        if (m.isKeyframe()) {
          kfs.push_back(frames.size());
          if (m.lost) lost_kfs.push_back(m.keyframe_index);
        }
        frames.push_back(m);
      }
      while (auto c = q_cal.tryPop()) {
        progress = true;
        if (c->end) {
          cal_ended = true;
          for (auto& p : pairing) p.endOfScans();
        } else {
          pairing[std::size_t(c->lane)].addScan(std::move(c->scan));
        }
      }
      if (progress) {
        const MappingView view{frames, kfs, lost_kfs, latest, mapping_ended};
        out.clear();
        for (auto& p : pairing) p.poll(view, out);
        for (auto& c : out) {
          rec_pairing.record(c.t0_ns);
          q_cand.push(CandItem{std::move(c), false});
        }
      }
      if (mapping_ended && cal_ended) {
        q_cand.push(CandItem{{}, true});
        return;
      }
      if (!progress) wake_pairing.wait(kPollTimeout.count());
    }
  }

  // ---- selector -----------------------------------------------------------------------------------------

  std::shared_ptr<const Scan> storedCloud(std::size_t i) const {
    std::lock_guard lock(store_mutex);
    return i < stored_clouds.size() ? stored_clouds[i] : nullptr;
  }

  /// Drops the store's reference to clouds before `bound`, keeping the dense window of the last keyframe.
  void releaseBefore(std::size_t bound) {
    std::lock_guard lock(store_mutex);
    const int n = params.dense_pointcloud_num_keyframes;
    if (!stored_keyframes.empty()) {
      const std::size_t recent = stored_keyframes[std::size_t(std::max(0, int(stored_keyframes.size()) - 1 - 2 * n))];
      bound = std::min(bound, recent);
    } else {
      bound = 0;
    }
    for (std::size_t i = 0; i < std::min(bound, stored_clouds.size()); ++i) stored_clouds[i].reset();
  }

  void deliver(const std::shared_ptr<const CalibrationDataset>& d, std::size_t lane) {
    lanes[lane]->handed_over.store(true);
    if (on_dataset) on_dataset(d);
  }

  void selectorStage() {
    std::vector<SelectionLane> selection;
    for (std::size_t i = 0; i < T_mapping_calib.size(); ++i)
      selection.emplace_back(sensors[0], sensors[i + 1], T_base_mapping, T_mapping_calib[i], params);
    const CloudLookup lookup = [this](std::size_t i) { return storedCloud(i); };
    while (!abort.load()) {
      auto item = q_cand.pop(kPollTimeout);
      if (!item) continue;
      if (item->end) {
        std::vector<Shortfall> missing;
        for (std::size_t i = 0; i < selection.size(); ++i) {
          if (auto d = selection[i].finish()) deliver(d, i);
          else if (!selection[i].handedOver()) missing.push_back(selection[i].shortfall());
        }
        std::lock_guard lock(result_mutex);
        shortfalls = std::move(missing);
        return;
      }
      const std::size_t lane = std::size_t(item->c.lane);
      std::vector<std::size_t> kfs;
      for (std::size_t i = 0; i < item->c.frames->size(); ++i)
        if ((*item->c.frames)[i].isKeyframe()) kfs.push_back(i);
      const std::int64_t t0 = item->c.t0_ns;
      auto d = selection[lane].add(std::move(item->c), lookup);
      LaneCounters& lc = *lanes[lane];
      lc.candidates.store(selection[lane].candidates());
      lc.accepted.store(selection[lane].accepted());
      lc.selected.store(selection[lane].selected());
      rec_selector.record(t0);
      if (d) deliver(d, lane);
      std::size_t bound = SIZE_MAX;
      for (const auto& s : selection)
        if (auto from = s.neededFrom(kfs)) bound = std::min(bound, *from);
      releaseBefore(bound);
    }
  }

  // ---- sources ------------------------------------------------------------------------------------------

  void waitForMappingLead(TimeNs stamp) {
    std::unique_lock lock(lead_mutex);
    lead_cv.wait(lock, [&] {
      return mapping_source_done || source_stop.load() || stamp <= mapping_ingested_stamp + kCalibrationLeadNs;
    });
  }

  void mappingIngested(TimeNs stamp, bool done) {
    {
      std::lock_guard lock(lead_mutex);
      if (done) mapping_source_done = true;
      else mapping_ingested_stamp = std::max(mapping_ingested_stamp, stamp);
    }
    lead_cv.notify_all();
  }

  void setUpSources() {
    if (options.input == InputKind::kPcap || options.input == InputKind::kLive) {
      DriverInput in;
      if (options.input == InputKind::kPcap) {
        in.pcap = options.pcap;
        in.rate = options.rate;
      }
      const bool throttle = options.input == InputKind::kPcap && !realtime;
      for (std::size_t s = 0; s < sensors.size(); ++s) {
        const int sensor = int(s);
        drivers.push_back(std::make_unique<SensorDriver>(
            rig.sensor(sensors[s]), in, source_stop, [this, sensor, throttle](Scan&& scan) {
              const std::int64_t t0 = steadyNs();
              if (throttle && sensor > 0) waitForMappingLead(scan.stamp_ns);
              const TimeNs stamp = scan.stamp_ns;
              ingest(std::move(scan), sensor, t0);
              if (throttle && sensor == 0) mappingIngested(stamp, false);
            }));
        driver_sensor.push_back(sensor);
      }
    } else if (options.input == InputKind::kShm) {
      for (const auto& name : sensors) {
        shm::ReaderOptions ro;
        ro.sensor = name;
        ro.name_prefix = options.shm_prefix;
        ro.start_at = realtime ? shm::ReaderOptions::StartAt::kNext : shm::ReaderOptions::StartAt::kOldest;
        readers.push_back(std::make_unique<shm::ScanRingReader>(ro));
      }
    }
  }

  void startSources() {
    std::lock_guard lock(sources_mutex);
    for (std::size_t d = 0; d < drivers.size(); ++d) {
      ++sources_running;
      sources.emplace_back("drv:" + sensors[std::size_t(driver_sensor[d])], options.cores, [this, d] {
        drivers[d]->run();
        if (driver_sensor[d] == 0) mappingIngested(0, true);
        --sources_running;
      });
    }
    for (std::size_t r = 0; r < readers.size(); ++r) {
      ++sources_running;
      sources.emplace_back("shm:" + sensors[r], options.cores, [this, r] {
        Scan scan;
        shm::ScanMeta meta;
        bool got_any = false;
        while (!source_stop.load()) {
          const auto st = readers[r]->read(scan, std::chrono::milliseconds(100), &meta);
          if (st == shm::ReadStatus::kScan) {
            got_any = true;
            ingest(Scan(scan), int(r), meta.publish_ns);
          } else if (st == shm::ReadStatus::kWriterGone && got_any) {
            break;
          }
        }
        --sources_running;
      });
    }
  }

  void startStages() {
    stages.emplace_back("deskew", options.cores, [this] { deskewStage(); });
    stages.emplace_back("mapper", options.cores, [this] { mapperStage(); });
    stages.emplace_back("pairing", options.cores, [this] { pairingStage(); });
    stages.emplace_back("selector", options.cores, [this] { selectorStage(); });
  }

  // Stops the driver threads / ring readers and waits for them (caller holds finish_mutex).
  void stopSources() {
    source_stop.store(true);
    lead_cv.notify_all();
    std::lock_guard sources_lock(sources_mutex);
    for (auto& s : sources) s.join();
  }

  void finish() {
    std::lock_guard lock(finish_mutex);
    if (finished) return;
    stopSources();
    for (const auto& r : readers) ring_overruns += r->stats().overruns + r->stats().torn_reads;
    endOfInput();
    for (auto& s : stages) s.join();
    wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
    finished = true;
  }

  void shutdown() {
    {
      std::lock_guard lock(finish_mutex);
      if (finished) return;
      stopSources();
      abort.store(true);
      for (auto* q : {&q_in, &q_map}) q->close();
      q_pose.close();
      q_frames.close();
      q_cal.close();
      q_cand.close();
      wake_deskew.signal();
      wake_pairing.signal();
      for (auto& s : stages) s.join();
      finished = true;
    }
  }
};

Pipeline::Pipeline(const config::RigConfig& rig, const PipelineOptions& options, DatasetCallback on_dataset)
    : impl_(std::make_unique<Impl>(rig, options, std::move(on_dataset))) {
  impl_->setUpSources();
  impl_->startStages();
}

Pipeline::~Pipeline() { impl_->shutdown(); }

void Pipeline::push(Scan scan) {
  const int sensor = impl_->sensorIndex(scan.sensor_id);
  impl_->ingest(std::move(scan), sensor, steadyNs());
}

void Pipeline::run(const std::atomic<bool>& stop) {
  if (impl_->options.input == InputKind::kInProcess)
    throw std::logic_error("Pipeline::run() needs a pcap, live or shm input; in process, push() then finish()");
  impl_->startSources();
  while (impl_->sources_running.load() > 0 && !stop.load()) std::this_thread::sleep_for(std::chrono::milliseconds(20));
  finish();
}

void Pipeline::finish() { impl_->finish(); }

PipelineProgress Pipeline::progress() const {
  const Impl& m = *impl_;
  PipelineProgress p;
  p.mapping_scans = m.mapping_scans.load();
  p.registered = m.registered.load();
  p.stored_frames = m.stored.load();
  p.keyframes = m.keyframes.load();
  p.stopped_frames = m.stopped.load();
  p.lost_frames = m.lost.load();
  p.mapping_done = m.mapping_done.load();
  for (std::size_t i = 0; i < m.lanes.size(); ++i) {
    const LaneCounters& c = *m.lanes[i];
    LidarProgress l;
    l.sensor = m.sensors[i + 1];
    l.scans = c.scans.load();
    l.candidates = c.candidates.load();
    l.accepted = c.accepted.load();
    l.selected = c.selected.load();
    l.budget = m.params.lidar_calibration_max_frames;
    l.handed_over = c.handed_over.load();
    p.lidars.push_back(l);
  }
  return p;
}

PipelineStats Pipeline::stats() const {
  const Impl& m = *impl_;
  PipelineStats s;
  s.wall_seconds = m.finished.load() ? m.wall_seconds.load()
                              : std::chrono::duration<double>(std::chrono::steady_clock::now() - m.started).count();
  const StageRecord* records[] = {&m.rec_ingest, &m.rec_deskew, &m.rec_mapper, &m.rec_pairing, &m.rec_selector};
  for (const StageRecord* r : records) {
    StageStats st;
    st.name = r->name;
    {
      std::lock_guard lock(r->mutex);
      st.latency = r->latency;
      st.processed = r->processed;
    }
    for (const auto& t : m.stages)
      if (t.name() == r->name) st.cpu_seconds = t.cpuSeconds();
    s.stages.push_back(std::move(st));
  }
  std::lock_guard sources_lock(m.sources_mutex);
  for (const auto& t : m.sources) {
    StageStats st;
    st.name = t.name();
    st.cpu_seconds = t.cpuSeconds();
    s.stages.push_back(std::move(st));
  }
  const auto queue = [&](const std::string& name, const auto& q) {
    s.queues.push_back({name, q.capacity(), q.depth(), q.maxDepth(), q.dropped()});
  };
  queue("input→deskew", m.q_in);
  queue("deskew→mapper", m.q_map);
  queue("deskew→pairing", m.q_cal);
  queue("mapper→pairing", m.q_frames);
  queue("mapper→deskew", m.q_pose);
  queue("pairing→selector", m.q_cand);
  s.input_dropped_scans = m.ring_overruns;
  return s;
}

MappingResult Pipeline::mapping() const {
  const Impl& m = *impl_;
  MappingResult r;
  r.mapping_sensor = m.sensors[0];
  r.T_base_mapping = m.T_base_mapping;
  {
    std::lock_guard lock(m.mapper_mutex);
    r.trajectory = m.trajectory;
    r.map_cloud = m.mapper.mapCloud();
  }
  std::lock_guard lock(m.store_mutex);
  if (m.stored_keyframes.empty()) {
    r.dense_cloud = std::make_shared<const Scan>();
    return r;
  }
  const MappingFrame& last_kf = m.stored_frames[m.stored_keyframes.back()];
  for (std::size_t i = 0; i < r.trajectory.size(); ++i)
    if (r.trajectory[i].sequence == last_kf.sequence) r.last_keyframe_frame = int(i);
  const int n = m.params.dense_pointcloud_num_keyframes;
  const std::size_t first = m.stored_keyframes[std::size_t(std::max(0, int(m.stored_keyframes.size()) - 1 - n))];
  registration::PointCloud merged;
  for (std::size_t i = first; i < m.stored_frames.size(); ++i) {
    if (!m.stored_clouds[i]) continue;
    const registration::PointCloud c = registration::transformed(registration::fromScan(*m.stored_clouds[i]),
                                                                 m.stored_frames[i].T_map_lidar);
    merged.points.insert(merged.points.end(), c.points.begin(), c.points.end());
  }
  auto dense = std::make_shared<Scan>();
  dense->sensor_id = m.sensors[0];
  dense->stamp_ns = last_kf.stamp_ns;
  if (!merged.empty()) {
    for (const auto& p : registration::voxelDownsample(merged, m.params.leaf_size_dense_map).points)
      dense->push_back(Point{float(p.x()), float(p.y()), float(p.z()), 0.0f, 0, last_kf.stamp_ns, 0});
  }
  r.dense_cloud = std::move(dense);
  return r;
}

std::vector<Shortfall> Pipeline::shortfalls() const {
  std::lock_guard lock(impl_->result_mutex);
  return impl_->shortfalls;
}

}  // namespace rigcal::pipeline
