#pragma once
// The pairing stage's work for one calibration lidar: for each mapping keyframe (after
// calibration_skip_keyframes) the nearest deskewed calibration scan, its interpolated mapping pose and
// statistics (pairKeyframe), crop-z and size filters. Everything waits for data, never for time (in
// offline mode), so the candidates are the same on every run: a keyframe is paired once a scan after it
// exists, the frames after the scan exist, and keyframe kid + dense_pointcloud_num_keyframes exists (its
// dense window is complete) — or the input ended.
#include <cstdint>
#include <deque>
#include <memory>
#include <string>
#include <vector>

#include "rigcal/config/parameters.hpp"
#include "rigcal/core/scan.hpp"
#include "rigcal/pipeline/pairing.hpp"
#include "rigcal/registration/point_to_plane_information.hpp"

namespace rigcal::pipeline {

/// A calibration-lidar scan after the deskew stage.
struct DeskewedScan {
  std::shared_ptr<const Scan> raw;
  std::shared_ptr<const Scan> deskewed;  // through the mapping trajectory and the initial extrinsic
  std::int64_t t0_ns = 0;                // steady clock when the scan was complete
};

/// One pairing handed to the selector.
struct CandidateMessage {
  int lane = 0;
  Pairing pairing;
  std::shared_ptr<const Scan> raw;
  /// Cropped, as stored in the dataset: positions only (x, y, z; the other arrays empty).
  std::shared_ptr<const Scan> deskewed;
  double information = 0.0;                   // pcaInformation() of deskewed
  registration::PointToPlaneInformation planes;  // frameInformation() of deskewed (ranking "information")
  int keyframe_index = 0;
  double path_length = 0.0;
  std::size_t window_begin = 0, window_end = 0;  // stored frames [begin, end] of the dense window
  std::vector<int> lost_keyframes;               // lost keyframe indices known when it was made
  std::shared_ptr<const std::vector<MappingFrame>> frames;  // the stored frames then
  std::int64_t t0_ns = 0;
};

/// What the pairing stage knows of the mapper, shared by the lanes.
struct MappingView {
  const std::vector<MappingFrame>& frames;      // stored frames, in order
  const std::vector<std::size_t>& keyframes;    // indices into frames
  const std::vector<int>& lost_keyframes;
  TimeNs latest_registered = 0;                 // stamp of the newest registered frame (stored or not)
  bool mapping_ended = false;
};

class PairingLane {
 public:
  PairingLane(int lane, const config::Parameters& params, const Pose& T_mapping_calib, bool realtime);
  void addScan(DeskewedScan scan);
  void endOfScans() { scans_ended_ = true; }
  /// Pairs every keyframe that can be paired now, appending to `out`.
  void poll(const MappingView& view, std::vector<CandidateMessage>& out);
  [[nodiscard]] std::uint64_t scans() const { return scans_received_; }

 private:
  enum class Step { kWait, kDone };
  Step pairNext(const MappingView& view, std::vector<CandidateMessage>& out);
  void prune(const MappingView& view);

  int lane_;
  config::Parameters params_;
  Pose T_mapping_calib_;
  bool realtime_;
  std::deque<DeskewedScan> scans_;  // by stamp
  bool scans_ended_ = false;
  std::size_t next_keyframe_ = 0;   // position in view.keyframes
  std::uint64_t scans_received_ = 0;
  std::shared_ptr<const std::vector<MappingFrame>> frames_snapshot_;
  TimeNs last_paired_stamp_ = 0;    // of the scan in the latest candidate
};

}  // namespace rigcal::pipeline
