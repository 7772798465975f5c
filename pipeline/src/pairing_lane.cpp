#include "pairing_lane.hpp"

#include <algorithm>
#include <limits>

#include "rigcal/pipeline/calibration_crop.hpp"
#include "rigcal/pipeline/frame_information.hpp"
#include "rigcal/pipeline/frame_selector.hpp"

namespace rigcal::pipeline {

namespace {
constexpr TimeNs kRealtimeGiveUpNs = 2 * kNsPerSec;  // real time: a lidar silent this long after a keyframe
constexpr TimeNs kKeepBeforeNs = 500 * kNsPerMs;     // scans kept before the oldest time still pairable

/// Calibration reads a candidate's cropped cloud as positions only; a lane holds one for every candidate
/// that may still be selected (issue #18): without the other arrays and the capacity the crop left, a
/// third of the bytes.
void keepPositionsOnly(Scan& s) {
  s.intensity = {};
  s.ring = {};
  s.offset_ns = {};
  s.return_index = {};
  s.x.shrink_to_fit();
  s.y.shrink_to_fit();
  s.z.shrink_to_fit();
}
}  // namespace

PairingLane::PairingLane(int lane, const config::Parameters& params, const Pose& T_mapping_calib, bool realtime)
    : lane_(lane), params_(params), T_mapping_calib_(T_mapping_calib), realtime_(realtime) {}

void PairingLane::addScan(DeskewedScan scan) {
  ++scans_received_;
  if (!scans_.empty() && scan.raw->stamp_ns <= scans_.back().raw->stamp_ns) return;  // out of order: ignore
  scans_.push_back(std::move(scan));
}

void PairingLane::poll(const MappingView& view, std::vector<CandidateMessage>& out) {
  while (next_keyframe_ < view.keyframes.size() && pairNext(view, out) == Step::kDone) ++next_keyframe_;
  prune(view);
}

void PairingLane::prune(const MappingView& view) {
  TimeNs oldest_needed = view.latest_registered;
  if (next_keyframe_ < view.keyframes.size())
    oldest_needed = std::min(oldest_needed, view.frames[view.keyframes[next_keyframe_]].stamp_ns);
  // Before the mapper registered anything latest_registered is the lowest time: nothing is old yet (and
  // subtracting the margin from it would overflow).
  if (oldest_needed < std::numeric_limits<TimeNs>::min() + kKeepBeforeNs) return;
  while (scans_.size() > 1 && scans_[1].raw->stamp_ns < oldest_needed - kKeepBeforeNs) scans_.pop_front();
}

PairingLane::Step PairingLane::pairNext(const MappingView& view, std::vector<CandidateMessage>& out) {
  const std::size_t kf_frame = view.keyframes[next_keyframe_];
  const MappingFrame& kf = view.frames[kf_frame];
  if (kf.keyframe_index < params_.calibration_skip_keyframes) return Step::kDone;
  const int n = params_.dense_pointcloud_num_keyframes;
  const bool window_complete = int(view.keyframes.size()) > kf.keyframe_index + n;
  if (!window_complete && !view.mapping_ended) return Step::kWait;

  // The nearest scan: needs one at or after the keyframe (or the end of this lidar's scans).
  const auto after = std::lower_bound(scans_.begin(), scans_.end(), kf.stamp_ns,
                                      [](const DeskewedScan& s, TimeNs t) { return s.raw->stamp_ns < t; });
  const bool gave_up = realtime_ && view.latest_registered > kf.stamp_ns + kRealtimeGiveUpNs;
  if (after == scans_.end() && !scans_ended_ && !gave_up && !view.mapping_ended) return Step::kWait;
  if (scans_.empty()) return Step::kDone;  // nothing from this lidar around the keyframe
  auto nearest = after;
  if (after == scans_.end() ||
      (after != scans_.begin() && kf.stamp_ns - std::prev(after)->raw->stamp_ns < after->raw->stamp_ns - kf.stamp_ns))
    nearest = std::prev(after);
  const DeskewedScan& scan = *nearest;
  // A lidar gone silent (its driver died or restarts): its last scan was offered with the first keyframe
  // after it; offering that one old scan again with every keyframe of the gap would re-pair it across it.
  if (after == scans_.end() && scan.raw->stamp_ns == last_paired_stamp_) return Step::kDone;

  std::optional<Pairing> pairing =
      pairKeyframe(view.frames, kf_frame, scan.raw->sequence, scan.raw->stamp_ns, params_);
  if (!pairing) return view.mapping_ended ? Step::kDone : Step::kWait;

  CandidateMessage c;
  c.lane = lane_;
  c.pairing = std::move(*pairing);
  c.raw = scan.raw;
  c.keyframe_index = kf.keyframe_index;
  c.path_length = kf.path_length;
  c.t0_ns = scan.t0_ns;
  last_paired_stamp_ = scan.raw->stamp_ns;
  const int first_kf = std::max(0, kf.keyframe_index - n);
  const int last_kf = std::min(int(view.keyframes.size()) - 1, kf.keyframe_index + n);
  c.window_begin = view.keyframes[std::size_t(first_kf)];
  c.window_end = view.keyframes[std::size_t(last_kf)];
  c.lost_keyframes = view.lost_keyframes;
  if (!frames_snapshot_ || frames_snapshot_->size() != view.frames.size())
    frames_snapshot_ = std::make_shared<const std::vector<MappingFrame>>(view.frames);
  c.frames = frames_snapshot_;

  if (c.pairing.accepted) {
    // Crop z in the mapping-lidar frame (through the initial extrinsic) and apply the range limits.
    auto cropped = std::make_shared<Scan>(*scan.deskewed);
    cropCalibrationCloud(*cropped, T_mapping_calib_, params_);
    if (int(cropped->size()) < params_.min_calibration_pointcloud_size) {
      c.pairing.accepted = false;
      c.pairing.rejection = std::to_string(cropped->size()) + " points after cropping < min_calibration_pointcloud_size " +
                            std::to_string(params_.min_calibration_pointcloud_size);
    } else {
      c.information = pcaInformation(*cropped);
      if (params_.calibration_frame_ranking != "pca") c.planes = frameInformation(*cropped);
      keepPositionsOnly(*cropped);
      c.deskewed = std::move(cropped);
    }
  }
  out.push_back(std::move(c));
  return Step::kDone;
}

}  // namespace rigcal::pipeline
