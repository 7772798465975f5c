// PairingLane (pipeline/src): a calibration lidar that goes silent while the mapping lidar keeps going (its
// ring writer died, issue 18) is not paired again and again with its one last scan across the gap.
#include <gtest/gtest.h>

#include <memory>
#include <vector>

#include "pairing_lane.hpp"
#include "rigcal/core/pose.hpp"

namespace rigcal::pipeline {
namespace {

constexpr TimeNs kPeriod = 100 * kNsPerMs;

TEST(PairingLane, ASilentLidarsLastScanIsPairedOnceNotWithEveryKeyframeOfTheGap) {
  config::Parameters params;
  params.calibration_skip_keyframes = 0;
  params.dense_pointcloud_num_keyframes = 0;
  // 10 s of mapping frames at 10 Hz; a keyframe each second.
  std::vector<MappingFrame> frames(100);
  for (int i = 0; i < 100; ++i) {
    frames[i].sequence = std::uint64_t(i);
    frames[i].stamp_ns = i * kPeriod;
    frames[i].path_length = 0.1 * i;  // 1 m/s along x
    frames[i].T_map_lidar = fromXyzRpy({0.1 * i, 0, 0, 0, 0, 0});
    frames[i].kind = FrameKind::kFrame;
  }
  std::vector<std::size_t> keyframes;
  for (std::size_t f = 10; f < frames.size(); f += 10) {
    frames[f].kind = FrameKind::kKeyframe;
    frames[f].keyframe_index = int(keyframes.size());
    keyframes.push_back(f);
  }
  const std::vector<int> lost;
  const MappingView view{frames, keyframes, lost, frames.back().stamp_ns, false};

  // The calibration lidar delivered for 1.5 s, then its writer died: no scan after.
  PairingLane lane(0, params, Pose::Identity(), /*realtime=*/true);
  for (int i = 0; i < 15; ++i) {
    auto scan = std::make_shared<Scan>();
    scan->sequence = std::uint64_t(i);
    scan->stamp_ns = i * kPeriod + 3 * kNsPerMs;
    lane.addScan({scan, scan, 0});
  }
  std::vector<CandidateMessage> out;
  lane.poll(view, out);

  // Keyframe 0 (1.0 s) has scans around it; keyframe 1 (2.0 s) gets the last scan (1.403 s), once; the
  // seven keyframes of the gap after it get nothing.
  ASSERT_EQ(out.size(), 2u);
  EXPECT_EQ(out[0].pairing.scan_sequence, 10u);
  EXPECT_EQ(out[1].pairing.scan_sequence, 14u);
  EXPECT_FALSE(out[1].pairing.accepted) << "0.6 s from its keyframe";
}

}  // namespace
}  // namespace rigcal::pipeline
