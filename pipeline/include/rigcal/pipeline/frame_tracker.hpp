#pragma once
// The upstream calibrator's frame rules, fed one registered mapping-lidar pose at a time:
// stored frame / keyframe / stopped / lost. Differences from upstream, on purpose:
//  - a registration that failed its convergence or fitness check makes the frame lost;
//  - the keyframe-lost check (direction change, interpolation error) fires as intended, except that after a
//    stopped keyframe the vehicle may set off backwards (a 180° flip of the travel direction is not lost);
//  - the tracker stops by itself after mapping_max_frames stored frames (bounded memory).
#include <deque>
#include <optional>
#include <vector>

#include "rigcal/config/parameters.hpp"
#include "rigcal/pipeline/mapping_frame.hpp"

namespace rigcal::pipeline {

class FrameTracker {
 public:
  explicit FrameTracker(const config::Parameters& params);

  /// Classifies the frame registered at `T_map_lidar` (registration_ok = converged and fit).
  /// The returned frame is also appended to frames() when it is stored.
  MappingFrame add(std::uint64_t sequence, TimeNs stamp_ns, const Pose& T_map_lidar, bool registration_ok);

  /// Stored frames (frames and keyframes), oldest first.
  [[nodiscard]] const std::vector<MappingFrame>& frames() const { return frames_; }
  /// Indices into frames() of the keyframes, oldest first.
  [[nodiscard]] const std::vector<std::size_t>& keyframes() const { return keyframes_; }
  /// True once mapping_max_frames frames are stored: the mapper is done.
  [[nodiscard]] bool full() const;
  /// The pose to start the next registration from: constant velocity from the last two stored
  /// frames, or the last pose when the vehicle stood still or the last frame was lost.
  [[nodiscard]] Pose predict(TimeNs stamp_ns) const;

 private:
  [[nodiscard]] std::optional<std::string> keyframeLostReason(const MappingFrame& candidate) const;

  config::Parameters params_;
  std::vector<MappingFrame> frames_;
  std::vector<std::size_t> keyframes_;
  std::optional<MappingFrame> last_processed_;  // the last registered frame, stored or not
  double last_processed_aux_delta_ = 0.0;       // its translation to the stored frame before it
  int stopped_in_a_row_ = 0;
};

}  // namespace rigcal::pipeline
