#include "selection_lane.hpp"

#include <algorithm>
#include <map>

namespace rigcal::pipeline {

SelectionLane::SelectionLane(std::string mapping_sensor, std::string calibration_sensor, const Pose& T_base_mapping,
                             const Pose& T_mapping_calib_guess, const config::Parameters& params)
    : params_(params) {
  base_.mapping_sensor = std::move(mapping_sensor);
  base_.calibration_sensor = std::move(calibration_sensor);
  base_.T_base_mapping = T_base_mapping;
  base_.T_mapping_calib_guess = T_mapping_calib_guess;
}

std::shared_ptr<const CalibrationDataset> SelectionLane::add(CandidateMessage candidate, const CloudLookup& clouds) {
  last_keyframe_ = std::max(last_keyframe_, candidate.keyframe_index);
  if (handed_over_) return nullptr;  // counted, no longer selected
  lost_keyframes_ = candidate.lost_keyframes;  // grows with every candidate
  if (candidate.frames) trajectory_ = candidate.frames;
  Record r;
  r.c = std::move(candidate);
  const bool selectable = r.c.pairing.accepted && r.c.information >= params_.calibration_min_pca_eigenvalue;
  if (r.c.pairing.accepted) ++accepted_;
  if (selectable) r.window = windowPicks(r.c, clouds);
  else release(r);
  r.c.frames.reset();  // a snapshot per candidate would add up over a drive: trajectory_ is the one needed
  records_.push_back(std::move(r));
  if (!records_.back().c.pairing.accepted) return nullptr;
  reselect();
  if (!selection_.budgetFull(params_)) return nullptr;
  return handOver(true);
}

std::vector<std::pair<std::size_t, MappingCloud>> SelectionLane::windowPicks(const CandidateMessage& c,
                                                                             const CloudLookup& clouds) const {
  const std::vector<MappingFrame>* frames = c.frames.get();
  if (frames == nullptr || c.pairing.keyframe_frame >= frames->size()) return {};
  const int own = (*frames)[c.pairing.keyframe_frame].keyframe_index;
  const int stride = targetKeyframeStride(params_.dense_pointcloud_num_keyframes, kTargetWindowClouds);
  std::vector<std::pair<std::size_t, MappingCloud>> picked;
  for (std::size_t i = c.window_begin; i <= c.window_end && i < frames->size(); ++i) {
    if (!isTargetCloud((*frames)[i], own, stride)) continue;
    auto cloud = clouds(i);
    if (cloud) picked.push_back({i, MappingCloud{(*frames)[i], std::move(cloud)}});
  }
  return picked;
}

void SelectionLane::release(Record& r) {
  r.window.clear();
  r.window.shrink_to_fit();
  r.c.raw.reset();
  r.c.deskewed.reset();
  r.c.frames.reset();
}

void SelectionLane::reselect() {
  std::vector<SelectionCandidate> pool;
  for (std::size_t id = 0; id < records_.size(); ++id) {
    const CandidateMessage& c = records_[id].c;
    if (c.pairing.accepted) pool.push_back({id, c.keyframe_index, c.path_length, c.information, c.planes});
  }
  selection_ = selectFrames(pool, lost_keyframes_, params_);
  // Too flat or near a lost keyframe stays so: those candidates' scans and clouds can go.
  for (const Rejection& r : selection_.rejected) {
    Record& rec = records_[r.id];
    if (rec.c.information < params_.calibration_min_pca_eigenvalue || r.reason.rfind("within ", 0) == 0)
      release(rec);
  }
}

std::shared_ptr<const CalibrationDataset> SelectionLane::finish() {
  if (handed_over_ || !selection_.enough(params_)) return nullptr;
  return handOver(false);
}

std::shared_ptr<const CalibrationDataset> SelectionLane::handOver(bool budget_full) {
  handed_over_ = true;
  auto d = dataset(budget_full);
  // The dataset holds the selected frames' scans and clouds; no other dataset will come from this lane:
  // every candidate is only counted from now on.
  for (Record& r : records_) release(r);
  trajectory_.reset();
  return d;
}

std::shared_ptr<const CalibrationDataset> SelectionLane::dataset(bool budget_full) const {
  auto d = std::make_shared<CalibrationDataset>(base_);
  d->budget_full = budget_full;
  for (const Record& r : records_) {
    d->candidates.push_back(r.c.pairing);
    if (!r.c.pairing.accepted)
      d->rejected.push_back({d->candidates.size() - 1, r.c.pairing.rejection});
  }
  for (const Rejection& r : selection_.rejected) d->rejected.push_back(r);
  std::sort(d->rejected.begin(), d->rejected.end(), [](const Rejection& a, const Rejection& b) { return a.id < b.id; });
  std::map<std::size_t, MappingCloud> window;  // by stored index: in sequence order, each once
  for (std::size_t id : selection_.selected)
    for (const auto& [idx, m] : records_[id].window) window.emplace(idx, m);
  std::map<std::size_t, std::size_t> position;  // stored index → index into mapping_clouds
  for (auto& [idx, m] : window) {
    position.emplace(idx, d->mapping_clouds.size());
    d->mapping_clouds.push_back(m);
  }
  for (std::size_t id : selection_.selected) {
    const Record& r = records_[id];
    CalibrationFrame f{r.c.pairing, r.c.raw, r.c.deskewed, r.c.information, {}};
    for (const auto& entry : r.window) f.window.push_back(position.at(entry.first));
    d->frames.push_back(std::move(f));
  }
  if (trajectory_) d->trajectory = *trajectory_;
  return d;
}

std::optional<std::size_t> SelectionLane::neededFrom(const std::vector<std::size_t>& keyframes) const {
  if (handed_over_) return std::nullopt;
  const int first = std::max(0, last_keyframe_ + 1 - params_.dense_pointcloud_num_keyframes);
  if (std::size_t(first) >= keyframes.size()) return keyframes.empty() ? 0 : keyframes.back();
  return keyframes[std::size_t(first)];
}

Shortfall SelectionLane::shortfall() const {
  Shortfall s;
  s.sensor = base_.calibration_sensor;
  s.selected = int(selection_.selected.size());
  s.required = params_.lidar_calibration_min_frames;
  s.message = std::to_string(s.selected) + " of " + std::to_string(s.required) + " frames for " + s.sensor +
              " (" + std::to_string(records_.size()) + " candidates, " + std::to_string(accepted_) +
              " accepted): drive further or lower lidar_calibration_min_frames";
  return s;
}

}  // namespace rigcal::pipeline

namespace rigcal::pipeline {

CandidateEvent SelectionLane::lastCandidateEvent(int lane) const {
  CandidateEvent e;
  e.lane = lane;
  if (records_.empty()) return e;
  const Pairing& p = records_.back().c.pairing;
  e.position = p.T_map_mapping_at_scan.translation().cast<float>();
  e.accepted = p.accepted;
  for (std::size_t id : selection_.selected)
    e.selected.push_back(records_[id].c.pairing.T_map_mapping_at_scan.translation().cast<float>());
  return e;
}

}  // namespace rigcal::pipeline
