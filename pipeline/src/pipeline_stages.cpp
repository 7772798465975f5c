// The pipeline's stage threads: deskew, mapper, pairing and selector, joined by BoundedQueues.
#include "pipeline_impl.hpp"

namespace rigcal::pipeline {

DeskewedScan Pipeline::Impl::deskewCalibration(const ScanItem& item, const TrajectoryBuffer& traj) const {
  auto out = std::make_shared<Scan>(*item.scan);
  // The calibration lidar's motion: the mapping trajectory seen through the extrinsic guess.
  if (!traj.empty())
    deskewThroughMapping(*out, [&](TimeNs t) { return traj.at(t); }, T_mapping_calib[std::size_t(item.sensor - 1)]);
  return DeskewedScan{item.scan, std::move(out), item.t0_ns};
}

void Pipeline::Impl::deskewStage() {
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
    // One input scan per round, then the held scans the trajectory now covers: while the mapper is the
    // bottleneck q_in is never empty, and draining it first held every calibration scan to the end of input.
    if (auto s = input_ended ? std::nullopt : q_in.tryPop()) {
      progress = true;
      if (s->end) {
        input_ended = true;
        q_map.push(std::move(*s));
      } else if (s->sensor == 0) {  // the mapper crops and deskews it
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
      const bool covered = traj_ended || (!traj.empty() && traj.last() >= h.scan->endTime());
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
    // Real time drops what comes this late anyway. Offline each driver reads the capture on its own
    // thread and a calibration lidar may come any time behind the mapping lidar: its scans need the poses
    // of their own time (a trimmed buffer extrapolated them, and selections differed from run to run), and
    // the poses of a whole drive are small (~140 B a mapping scan).
    if (realtime) {
      if (!held.empty()) traj.trimBefore(held.front().scan->stamp_ns - kNsPerSec);
      else if (!traj.empty()) traj.trimBefore(traj.last() - 2 * kNsPerSec);
    }
    if (input_ended && traj_ended && held.empty()) {
      q_cal.push(CalItem{0, {}, true});
      wake_pairing.signal();
      return;
    }
    if (!progress) wake_deskew.wait(kPollTimeout.count());
  }
}

void Pipeline::Impl::mapperStage() {
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
      out = mapper.process(std::move(*item->scan));
      if (out.registered) trajectory.push_back(out.frame);
    }
    item->scan.reset();
    if (!out.registered) {
      skipped.fetch_add(1);
      mapping_done.store(mapper.done());
      continue;
    }
    registered.fetch_add(1);
    const MappingFrame& f = out.frame;
    // The pose is out (scan-to-pose latency ends here); the dense cloud and the local-map feed come after.
    rec_mapper.record(item->t0_ns);
    q_pose.push(PoseItem{f.stamp_ns, f.T_map_lidar, false});
    wake_deskew.signal();
    {
      std::lock_guard lock(mapper_mutex);
      mapper.finishFrame(out);
    }
    if (f.stored()) {
      stored.fetch_add(1);
      std::lock_guard lock(store_mutex);
      if (f.isKeyframe()) stored_keyframes.push_back(stored_frames.size());
      stored_frames.push_back(f);
      stored_clouds.push_back(out.cloud);  // a keyframe's; null for the others (MapperOutput::cloud)
    }
    if (f.isKeyframe()) keyframes.fetch_add(1);
    if (f.kind == FrameKind::kStopped || f.kind == FrameKind::kStoppedKeyframe) stopped.fetch_add(1);
    if (f.lost) lost.fetch_add(1);
    if (options.observer) options.observer->onFrame(f, out.cloud);
    q_frames.push(FrameItem{std::move(out), false});
    wake_pairing.signal();
  }
}

void Pipeline::Impl::pairingStage() {
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

std::shared_ptr<const Scan> Pipeline::Impl::storedCloud(std::size_t i) const {
  std::lock_guard lock(store_mutex);
  return i < stored_clouds.size() ? stored_clouds[i] : nullptr;
}

/// Drops the store's reference to clouds before `bound`, keeping the dense window of the last keyframe.
void Pipeline::Impl::releaseBefore(std::size_t bound) {
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

void Pipeline::Impl::deliver(std::shared_ptr<const CalibrationDataset> d, std::size_t lane) {
  lanes[lane]->handed_over.store(true);
  if (on_dataset) on_dataset(std::move(d));
}

void Pipeline::Impl::selectorStage() {
  std::vector<SelectionLane> selection;
  for (std::size_t i = 0; i < T_mapping_calib.size(); ++i)
    selection.emplace_back(sensors[0], sensors[i + 1], T_base_mapping, T_mapping_calib[i], params);
  const CloudLookup lookup = [this](std::size_t i) { return storedCloud(i); };
  while (!abort.load()) {
    auto item = q_cand.pop(kPollTimeout);
    if (!item) continue;
    if (item->end) {
      std::vector<Shortfall> missing;
      // Every lane's dataset first: each then holds only its selected windows, and the other candidates'
      // clouds are gone before the first calibration (delivered offline) starts building targets.
      std::vector<std::pair<std::shared_ptr<const CalibrationDataset>, std::size_t>> ready;
      for (std::size_t i = 0; i < selection.size(); ++i) {
        if (auto d = selection[i].finish()) ready.emplace_back(std::move(d), i);
        else if (!selection[i].handedOver()) missing.push_back(selection[i].shortfall());
      }
      for (auto& [d, i] : ready) deliver(std::move(d), i);
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
    if (options.observer) options.observer->onCandidate(selection[lane].lastCandidateEvent(int(lane)));
    if (d) deliver(std::move(d), lane);
    std::size_t bound = SIZE_MAX;
    for (const auto& s : selection)
      if (auto from = s.neededFrom(kfs)) bound = std::min(bound, *from);
    releaseBefore(bound);
  }
}

void Pipeline::Impl::startStages() {
  stages.emplace_back("deskew", options.cores, [this] { deskewStage(); });
  stages.emplace_back("mapper", options.cores, [this] { mapperStage(); });
  stages.emplace_back("pairing", options.cores, [this] { pairingStage(); });
  stages.emplace_back("selector", options.cores, [this] { selectorStage(); });
}

}  // namespace rigcal::pipeline
