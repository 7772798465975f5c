// PairingLane (pipeline/src): a calibration lidar that goes silent while the mapping lidar keeps going (its
// ring writer died, issue 18) is not paired again and again with its one last scan across the gap.
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <vector>

#include "pairing_lane.hpp"
#include "rigcal/core/pose.hpp"

namespace rigcal::pipeline {
namespace {

constexpr TimeNs kLidarPeriod = 100 * kNsPerMs;

TEST(PairingLane, ASilentLidarsLastScanIsPairedOnceNotWithEveryKeyframeOfTheGap) {
  config::Parameters params;
  params.calibration_skip_keyframes = 0;
  params.dense_pointcloud_num_keyframes = 0;
  // 10 s of mapping frames at 10 Hz; a keyframe each second.
  std::vector<MappingFrame> frames(100);
  for (int i = 0; i < 100; ++i) {
    frames[i].sequence = std::uint64_t(i);
    frames[i].stamp_ns = i * kLidarPeriod;
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
    scan->stamp_ns = i * kLidarPeriod + 3 * kNsPerMs;
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

namespace rigcal::pipeline {
namespace {

// Issue #18: a lane's selector keeps the cropped cloud of every candidate that may still be selected, and
// calibration reads only its positions: the other arrays, and the capacity the crop left, are dropped.
TEST(PairingLane, ACandidatesCroppedCloudKeepsPositionsOnly) {
  config::Parameters params;
  params.calibration_skip_keyframes = 0;
  params.dense_pointcloud_num_keyframes = 0;
  params.min_calibration_pointcloud_size = 10;
  std::vector<MappingFrame> frames(30);
  for (int i = 0; i < 30; ++i) {
    frames[i].sequence = std::uint64_t(i);
    frames[i].stamp_ns = i * kLidarPeriod;
    frames[i].path_length = 0.1 * i;
    frames[i].T_map_lidar = fromXyzRpy({0.1 * i, 0, 0, 0, 0, 0});
    frames[i].kind = i == 10 ? FrameKind::kKeyframe : FrameKind::kFrame;
    frames[i].keyframe_index = i == 10 ? 0 : -1;
  }
  const std::vector<std::size_t> keyframes{10};
  const std::vector<int> lost;
  const MappingView view{frames, keyframes, lost, frames.back().stamp_ns, false};
  PairingLane lane(0, params, Pose::Identity(), /*realtime=*/false);
  for (int i = 8; i < 14; ++i) {
    auto scan = std::make_shared<Scan>();
    scan->sequence = std::uint64_t(i);
    scan->stamp_ns = i * kLidarPeriod + 3 * kNsPerMs;
    // 1000 points 2-10 m away (kept), 1000 within 1 m (cropped by min_calibration_range).
    for (int j = 0; j < 2000; ++j) {
      const double r = j < 1000 ? 2.0 + 0.008 * j : 0.5;
      const double a = 0.0063 * j;
      scan->push_back({float(r * std::cos(a)), float(r * std::sin(a)), float(0.001 * j - 1.0), 7.0F,
                       std::uint16_t(j % 16), scan->stamp_ns + j, 0});
    }
    lane.addScan({scan, scan, 0});
  }
  lane.endOfScans();
  std::vector<CandidateMessage> out;
  lane.poll(view, out);
  ASSERT_EQ(out.size(), 1u);
  ASSERT_TRUE(out[0].pairing.accepted) << out[0].pairing.rejection;
  ASSERT_NE(out[0].deskewed, nullptr);
  const Scan& cropped = *out[0].deskewed;
  EXPECT_EQ(cropped.size(), 1000u);
  EXPECT_EQ(cropped.y.size(), 1000u);
  EXPECT_EQ(cropped.z.size(), 1000u);
  EXPECT_TRUE(cropped.intensity.empty() && cropped.ring.empty() && cropped.offset_ns.empty() &&
              cropped.return_index.empty());
  EXPECT_EQ(cropped.x.capacity(), cropped.x.size()) << "the crop's spare capacity is given back";
  EXPECT_EQ(out[0].raw->intensity.size(), 2000u) << "the raw scan is as decoded";
}

}  // namespace
}  // namespace rigcal::pipeline
