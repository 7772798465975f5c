#pragma once
// A mapping-lidar frame as the mapper keeps it: its registered pose and the bookkeeping of the
// upstream rules (path length, speed, keyframe / stopped / lost flags).
#include <cstdint>
#include <string>

#include "rigcal/core/pose.hpp"
#include "rigcal/core/time.hpp"

namespace rigcal::pipeline {

enum class FrameKind : std::uint8_t {
  kDropped,          // too close to the previous frame and not stopped: not stored
  kFrame,            // stored to densify the map around keyframes
  kStopped,          // the vehicle stands still: not stored (until forced, below)
  kStoppedKeyframe,  // the N-th stopped frame in a row: stored as a keyframe
  kKeyframe,         // every new_keyframe_min_distance of path, the first frame, or after a loss
};

const char* toString(FrameKind kind);

struct MappingFrame {
  std::uint64_t sequence = 0;  // the scan's sequence number
  TimeNs stamp_ns = 0;
  Pose T_map_lidar = Pose::Identity();
  FrameKind kind = FrameKind::kDropped;
  bool lost = false;           // registration failed, too long unseen, or implausible motion
  std::string lost_reason;     // why, in a few words
  double path_length = 0.0;    // cumulative distance along stored frames, metres
  double delta = 0.0;          // translation to the previous stored frame, metres
  double speed = 0.0;          // delta / dt, m/s
  bool speed_known = false;    // false for the first frame: nothing to measure it against
  int keyframe_index = -1;     // index among keyframes (-1: not a keyframe)

  [[nodiscard]] bool stored() const {
    return kind == FrameKind::kFrame || kind == FrameKind::kKeyframe || kind == FrameKind::kStoppedKeyframe;
  }
  [[nodiscard]] bool isKeyframe() const {
    return kind == FrameKind::kKeyframe || kind == FrameKind::kStoppedKeyframe;
  }
};

}  // namespace rigcal::pipeline
