// SelectionLane (pipeline/src): what a calibration lidar's lane keeps while it waits for its frame budget
// (issue #18, peak memory). A candidate that may still be selected keeps only the mapping clouds its target
// would be built from (every other keyframe of its ~200-cloud window and its own: at most
// kTargetWindowClouds), neighbouring candidates share them, one that never can keeps no scan, and the
// hand-over carries each selected frame's picks.
#include <gtest/gtest.h>

#include <algorithm>
#include <memory>
#include <vector>

#include "selection_lane.hpp"
#include "rigcal/core/pose.hpp"
#include "rigcal/pipeline/target_window_picks.hpp"

namespace rigcal::pipeline {
namespace {

constexpr int kKeyframes = 40;
constexpr int kFramesPerKeyframe = 10;  // a keyframe, then 9 ordinary stored frames

/// A drive of stored mapping frames (one every 10 cm, a keyframe every metre) and the store of their
/// clouds, which the test can drop as the pipeline does once no future candidate needs them.
struct StoredDrive {
  config::Parameters params;
  std::shared_ptr<const std::vector<MappingFrame>> frames;
  std::vector<std::shared_ptr<const Scan>> store;
  std::vector<std::weak_ptr<const Scan>> watched;  // every cloud, to see which ones are still held

  StoredDrive() {
    params.lidar_calibration_max_frames = 2;
    params.calibration_min_distance_between_frames = 5.0;
    auto f = std::make_shared<std::vector<MappingFrame>>();
    for (int i = 0; i < kKeyframes * kFramesPerKeyframe; ++i) {
      MappingFrame m;
      m.sequence = std::uint64_t(100 + i);
      m.stamp_ns = TimeNs(i) * 100 * kNsPerMs;
      m.path_length = 0.1 * i;
      m.T_map_lidar = fromXyzRpy({0.1 * i, 0, 0, 0, 0, 0});
      const bool key = i % kFramesPerKeyframe == 0;
      m.kind = key ? FrameKind::kKeyframe : FrameKind::kFrame;
      m.keyframe_index = key ? i / kFramesPerKeyframe : -1;
      f->push_back(m);
      auto cloud = std::make_shared<Scan>();
      cloud->sequence = m.sequence;
      cloud->x = {float(i)};
      cloud->y = {0.0F};
      cloud->z = {0.0F};
      store.push_back(cloud);
      watched.push_back(cloud);
    }
    frames = f;
  }

  CloudLookup lookup() const {
    return [this](std::size_t i) { return i < store.size() ? store[i] : nullptr; };
  }

  /// The candidate of keyframe k, its window complete (keyframes k-n .. k+n, clamped to the drive).
  CandidateMessage candidate(int k, bool accepted, double information) const {
    const int n = params.dense_pointcloud_num_keyframes;
    CandidateMessage c;
    c.pairing.keyframe_frame = std::size_t(k * kFramesPerKeyframe);
    c.pairing.scan_sequence = std::uint64_t(k);
    c.pairing.accepted = accepted;
    if (!accepted) c.pairing.rejection = "accel too high";
    auto scan = std::make_shared<Scan>();
    scan->x = {1.0F, 2.0F, 3.0F};
    scan->y = scan->z = {0.0F, 0.0F, 0.0F};
    c.raw = scan;
    c.deskewed = std::make_shared<const Scan>(*scan);
    c.information = information;
    c.keyframe_index = k;
    c.path_length = (*frames)[c.pairing.keyframe_frame].path_length;
    c.window_begin = std::size_t(std::max(0, k - n) * kFramesPerKeyframe);
    c.window_end = std::size_t(std::min(kKeyframes - 1, k + n) * kFramesPerKeyframe);
    c.frames = frames;
    return c;
  }

  std::size_t cloudsHeld() const {
    return std::size_t(std::count_if(watched.begin(), watched.end(), [](const auto& w) { return !w.expired(); }));
  }
};

TEST(SelectionLane, ACandidateKeepsOnlyTheCloudsItsTargetWouldBeBuiltFrom) {
  StoredDrive drive;
  SelectionLane lane("top", "front", Pose::Identity(), Pose::Identity(), drive.params);
  // Keyframe 15's window is keyframes 5..25: 201 stored frames, of which it keeps keyframes 6, 8, .., 24
  // (every other one) and its own.
  ASSERT_EQ(lane.add(drive.candidate(15, true, 1.0), drive.lookup()), nullptr);
  drive.store.clear();  // the pipeline's store moved on: only what the lane holds is left
  EXPECT_EQ(drive.cloudsHeld(), 11u) << "of a 201-cloud window";
  for (int k = 5; k <= 25; ++k) {
    const bool kept = !drive.watched[std::size_t(k * kFramesPerKeyframe)].expired();
    EXPECT_EQ(kept, k % 2 == 0 || k == 15) << "keyframe " << k;
  }
}

TEST(SelectionLane, NeighbouringCandidatesShareTheirClouds) {
  StoredDrive drive;
  drive.params.lidar_calibration_max_frames = 10;  // none is handed over: the lane holds all three
  SelectionLane lane("top", "front", Pose::Identity(), Pose::Identity(), drive.params);
  for (const int k : {14, 15, 16}) ASSERT_EQ(lane.add(drive.candidate(k, true, 1.0), drive.lookup()), nullptr);
  drive.store.clear();
  // Keyframes 4..26 on the stride (12) and 15, each held once: picks spread within each window had held
  // 3 x 12 different clouds.
  EXPECT_EQ(drive.cloudsHeld(), 13u);
}

TEST(SelectionLane, ACandidateThatCanNeverBeSelectedKeepsNoScanNorCloud) {
  StoredDrive drive;
  SelectionLane lane("top", "front", Pose::Identity(), Pose::Identity(), drive.params);
  CandidateMessage rejected = drive.candidate(12, false, 1.0);  // its pairing failed the criteria
  CandidateMessage flat = drive.candidate(14, true, 0.1);       // below calibration_min_pca_eigenvalue
  const std::weak_ptr<const Scan> rejected_raw = rejected.raw, flat_raw = flat.raw, flat_deskewed = flat.deskewed;
  ASSERT_EQ(lane.add(std::move(rejected), drive.lookup()), nullptr);
  ASSERT_EQ(lane.add(std::move(flat), drive.lookup()), nullptr);
  EXPECT_TRUE(rejected_raw.expired());
  EXPECT_TRUE(flat_raw.expired());
  EXPECT_TRUE(flat_deskewed.expired());
  drive.store.clear();
  EXPECT_EQ(drive.cloudsHeld(), 0u);
  EXPECT_EQ(lane.candidates(), 2u) << "still counted";
}

TEST(SelectionLane, TheHandOverCarriesEachSelectedFramesPicksAndTheLaneKeepsNothing) {
  StoredDrive drive;
  SelectionLane lane("top", "front", Pose::Identity(), Pose::Identity(), drive.params);
  CandidateMessage later_flat = drive.candidate(20, true, 0.1);
  const std::weak_ptr<const Scan> unselected_raw = later_flat.raw;
  ASSERT_EQ(lane.add(drive.candidate(12, true, 1.0), drive.lookup()), nullptr);
  ASSERT_EQ(lane.add(std::move(later_flat), drive.lookup()), nullptr);
  // Keyframe 18's window (8..28) overlaps keyframe 12's (2..22): they share keyframes 8, 10, .., 22.
  const auto d = lane.add(drive.candidate(18, true, 1.0), drive.lookup());
  ASSERT_NE(d, nullptr) << "the budget of 2 frames is full";
  ASSERT_EQ(d->frames.size(), 2u);
  EXPECT_TRUE(unselected_raw.expired());
  std::vector<std::uint64_t> all;
  for (const auto& f : d->frames) {
    ASSERT_EQ(f.window.size(), 11u);
    std::vector<std::uint64_t> sequences;
    for (const std::size_t i : f.window) {
      ASSERT_LT(i, d->mapping_clouds.size());
      sequences.push_back(d->mapping_clouds[i].frame.sequence);
      EXPECT_EQ(d->mapping_clouds[i].cloud->sequence, d->mapping_clouds[i].frame.sequence);
    }
    EXPECT_TRUE(std::is_sorted(sequences.begin(), sequences.end()));
    // Its own keyframe's cloud, and the window's first and last keyframes.
    const std::uint64_t own = d->trajectory[f.pairing.keyframe_frame].sequence;
    const int k = d->trajectory[f.pairing.keyframe_frame].keyframe_index;
    EXPECT_NE(std::find(sequences.begin(), sequences.end(), own), sequences.end()) << "keyframe " << k;
    EXPECT_EQ(sequences.front(), 100u + std::uint64_t(std::max(0, k - 10) * kFramesPerKeyframe));
    EXPECT_EQ(sequences.back(), 100u + std::uint64_t(std::min(kKeyframes - 1, k + 10) * kFramesPerKeyframe));
  }
  // The hand-over's clouds are the two frames' picks, each once, by sequence.
  for (std::size_t i = 1; i < d->mapping_clouds.size(); ++i)
    EXPECT_LT(d->mapping_clouds[i - 1].frame.sequence, d->mapping_clouds[i].frame.sequence);
  EXPECT_EQ(d->mapping_clouds.size(), 14u) << "keyframes 2, 4, .., 28: the windows share 8 of their 11";
  drive.store.clear();
  EXPECT_EQ(drive.cloudsHeld(), d->mapping_clouds.size()) << "the lane keeps none after the hand-over";
}

TEST(TargetWindowPicks, EveryStrideThKeyframeAndTheFramesOwn) {
  EXPECT_EQ(targetKeyframeStride(10, 12), 2) << "the defaults: 11 keyframes of 21, and the own";
  EXPECT_EQ(targetKeyframeStride(20, 12), 4);
  EXPECT_EQ(targetKeyframeStride(5, 12), 1) << "a window of 11 keyframes fits whole";
  EXPECT_EQ(targetKeyframeStride(0, 12), 1);
  EXPECT_EQ(targetKeyframeStride(10, 0), 21) << "no room: one keyframe a window, and the own";
  MappingFrame f;
  f.kind = FrameKind::kKeyframe;
  f.keyframe_index = 8;
  EXPECT_TRUE(isTargetCloud(f, 15, 2));
  f.keyframe_index = 9;
  EXPECT_FALSE(isTargetCloud(f, 15, 2));
  EXPECT_TRUE(isTargetCloud(f, 9, 2)) << "its own";
  f.kind = FrameKind::kStoppedKeyframe;
  f.keyframe_index = 10;
  EXPECT_TRUE(isTargetCloud(f, 15, 2));
  f.kind = FrameKind::kFrame;
  f.keyframe_index = -1;
  EXPECT_FALSE(isTargetCloud(f, 15, 1)) << "ordinary stored frames are never picked";
}

TEST(TargetWindowPicks, EvenlySpreadWithTheKeyframesOwnCloud) {
  EXPECT_EQ(spreadWindowPicks(5, 2, 12), (std::vector<std::size_t>{0, 1, 2, 3, 4}));
  EXPECT_EQ(spreadWindowPicks(201, 100, 0).size(), 201u) << "0 = all";
  const auto picks = spreadWindowPicks(201, 100, 12);
  ASSERT_EQ(picks.size(), 12u);
  EXPECT_EQ(picks.front(), 0u);
  EXPECT_EQ(picks.back(), 200u);
  EXPECT_NE(std::find(picks.begin(), picks.end(), 100u), picks.end());
  EXPECT_TRUE(std::is_sorted(picks.begin(), picks.end()));
  // 201 clouds in 11 gaps: 0, 18, 36, 54, 72, 90, 109, ... (k·200/11); 100 replaces the nearest pick, 109.
  EXPECT_EQ(picks[5], 90u);
  EXPECT_EQ(picks[6], 100u);
  EXPECT_EQ(picks[7], 127u);
}

}  // namespace
}  // namespace rigcal::pipeline
