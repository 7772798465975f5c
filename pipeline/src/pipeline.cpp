#include "rigcal/pipeline/pipeline.hpp"

#include "pipeline_impl.hpp"
#include "rigcal/pipeline/clock_offset_estimate.hpp"

namespace rigcal::pipeline {

int Pipeline::Impl::sensorIndex(const std::string& name) const {
  for (std::size_t i = 0; i < sensors.size(); ++i)
    if (sensors[i] == name) return int(i);
  return -1;
}

void Pipeline::Impl::finish() {
  std::lock_guard lock(finish_mutex);
  if (finished) return;
  stopSources();
  for (const auto& r : readers) ring_overruns += r->stats().overruns + r->stats().torn_reads;
  endOfInput();
  for (auto& s : stages) s.join();
  wall_seconds = std::chrono::duration<double>(std::chrono::steady_clock::now() - started).count();
  finished = true;
}

void Pipeline::Impl::shutdown() {
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
  p.skipped = m.skipped.load();
  p.stored_frames = m.stored.load();
  p.keyframes = m.keyframes.load();
  p.stopped_frames = m.stopped.load();
  p.lost_frames = m.lost.load();
  p.mapping_done = m.mapping_done.load();
  p.mapping_sensor = m.sensors[0];
  p.mapping_lost_packets = m.mapping_lost_packets.load();
  p.mapping_malformed_packets = m.mapping_malformed_packets.load();
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
    l.lost_packets = c.lost_packets.load();
    l.malformed_packets = c.malformed_packets.load();
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

MappingResult Pipeline::mapping(bool with_dense_cloud) const {
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
    if (with_dense_cloud) r.dense_cloud = std::make_shared<const Scan>();
    return r;
  }
  const MappingFrame& last_kf = m.stored_frames[m.stored_keyframes.back()];
  for (std::size_t i = 0; i < r.trajectory.size(); ++i)
    if (r.trajectory[i].sequence == last_kf.sequence) r.last_keyframe_frame = int(i);
  if (!with_dense_cloud) return r;
  const int n = m.params.dense_pointcloud_num_keyframes;
  const std::size_t first = m.stored_keyframes[std::size_t(std::max(0, int(m.stored_keyframes.size()) - 1 - n))];
  registration::PointCloud merged;
  for (std::size_t i = first; i < m.stored_frames.size(); ++i) {
    if (!m.stored_clouds[i]) continue;
    const registration::PointCloud c = registration::transformed(registration::fromScan(*m.stored_clouds[i]),
                                                                 m.stored_frames[i].T_map_lidar);
    merged.points.insert(merged.points.end(), c.points.begin(), c.points.end());
  }
  Scan like;
  like.sensor_id = m.sensors[0];
  like.stamp_ns = last_kf.stamp_ns;
  r.dense_cloud = std::make_shared<const Scan>(
      merged.empty() ? like : registration::toScan(registration::voxelDownsample(merged, m.params.leaf_size_dense_map), like));
  return r;
}

std::vector<SensorInput> Pipeline::inputs() const {
  std::vector<SensorInput> out;
  std::lock_guard lock(impl_->sources_mutex);  // the driver threads are joined after finish()
  for (std::size_t d = 0; d < impl_->drivers.size(); ++d) {
    const SensorDriver& drv = *impl_->drivers[d];
    const auto& a = drv.assemblerStats();
    const auto& src = drv.sourceStats();
    SensorInput in;
    in.sensor = impl_->sensors[std::size_t(impl_->driver_sensor[d])];
    in.packets = a.packets;
    in.lost_packets = a.lost_packets;
    in.malformed = a.malformed + src.malformed;
    in.late_dropped = a.late_dropped;
    in.reordered = a.reordered;
    in.foreign_packets = drv.foreignPackets().packets;
    if (in.foreign_packets > 0) {
      const config::SensorConfig& sc = impl_->rig.sensor(in.sensor);
      in.foreign = drv.foreignPackets().describe(sc.model, sc.source.port);
    }
    in.fragments_dropped = src.fragments_dropped;
    in.last_error = a.last_error;
    in.warning = drv.warning();
    in.clock_lag_ms = drv.clockLagMs();
    const ClockLag lag = clockLagOf(drv.clockLagSamplesMs());
    in.clock_lag_sigma_ms = lag.sigma_ms;
    in.clock_lag_sweeps = lag.sweeps;
    out.push_back(std::move(in));
  }
  // Rings: what each sensor's driver process counted, as far as the scans read from its ring tell.
  for (std::size_t r = 0; r < impl_->ring_tallies.size(); ++r) {
    const RingInputTotals t = impl_->ring_tallies[r]->totals();
    SensorInput in;
    in.sensor = impl_->sensors[r];
    in.packets = t.packets;
    in.lost_packets = r == 0 ? impl_->mapping_lost_packets.load() : impl_->lanes[r - 1]->lost_packets.load();
    in.malformed = t.malformed;
    in.late_dropped = t.late_dropped;
    in.reordered = t.reordered;
    in.foreign_packets = t.foreign;
    if (t.foreign > 0) in.foreign = "packets of another model on its port (its driver process names them)";
    out.push_back(std::move(in));
  }
  return out;
}

std::vector<Shortfall> Pipeline::shortfalls() const {
  std::lock_guard lock(impl_->result_mutex);
  return impl_->shortfalls;
}

}  // namespace rigcal::pipeline
