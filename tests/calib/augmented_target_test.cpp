// The near crop of a later frame's augmented target (SourceNeighbourhood): every mapping point within its
// radius of the placed source is kept, so the scores and the coarse registrations see what the box crop
// gave them, on fewer points. And the window of mapping clouds a frame's target is built from.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <map>
#include <memory>
#include <vector>

#include "lidar_lidar_sim_dataset.hpp"
#include "rigcal/calib/lidar_lidar/augmented_target.hpp"
#include "rigcal/calib/lidar_lidar/calibration_score.hpp"
#include "rigcal/calib/lidar_lidar/calibration_source.hpp"
#include "rigcal/calib/lidar_lidar/source_neighbourhood.hpp"
#include "rigcal/registration/target.hpp"

namespace rigcal::calib {
namespace {

// Two placements 100 m apart keep their cells a bit each; 30 km apart on every axis, in a hash set (a bit
// each would take far more than its 8 MB bound). Both must hold the same cells around each placed point.
TEST(SourceNeighbourhood, HoldsEveryPointWithinTheRadiusAndNothingFarBeyond) {
  registration::PointCloud source;
  source.points = {{0.0, 0.0, 0.0, 1.0}, {10.3, -4.7, 1.2, 1.0}};
  const double radius = 0.6;
  for (const Eigen::Vector3d& offset : {Eigen::Vector3d(100.0, 0.0, 0.0), Eigen::Vector3d(3e4, -3e4, 3e4)}) {
    const Pose shift(Eigen::Translation3d{offset});
    const SourceNeighbourhood near(source, {Pose::Identity(), shift}, radius);
    EXPECT_LE(near.cells(), 2u * 2u * 27u);
    EXPECT_GE(near.cells(), 2u * 27u);
    for (const Pose& T : {Pose::Identity(), shift}) {
      for (const auto& p : source.points) {
        const Eigen::Vector3d c = T * p.head<3>();
        // Points on a sphere just inside the radius around each placed source point are all held.
        for (int i = 0; i < 200; ++i) {
          const double z = -1.0 + 2.0 * (i + 0.5) / 200.0, a = 2.399963 * i;
          const Eigen::Vector3d dir(std::sqrt(1 - z * z) * std::cos(a), std::sqrt(1 - z * z) * std::sin(a), z);
          EXPECT_TRUE(near.contains(c + 0.999 * radius * dir)) << "around " << c.transpose();
          EXPECT_FALSE(near.contains(c + 2.0 * std::sqrt(3.0) * radius * 1.001 * dir)) << "around " << c.transpose();
        }
      }
    }
    EXPECT_FALSE(near.contains(offset / 2.0));
    EXPECT_FALSE(near.contains({NAN, 0.0, 0.0}));
    EXPECT_FALSE(near.contains({1e300, 0.0, 0.0}));
  }
  EXPECT_FALSE(SourceNeighbourhood(registration::PointCloud{}, {Pose::Identity()}, radius).contains({0.0, 0.0, 0.0}));
  EXPECT_THROW(SourceNeighbourhood(source, {Pose::Identity()}, 0.0), std::invalid_argument);
}

// On the parking lot: the near target (source under the guess and the truth) scores the truth and the
// guess exactly as the box target does, and is much smaller.
TEST(AugmentedTarget, NearCropKeepsTheScoresOfItsPosesOnFewerPoints) {
  const auto& data = test::flatParkingLot();
  const auto& d = data.datasets.front();
  const Pose truth = data.truth_T_mapping_calib.at(d.calibration_sensor);
  const std::size_t frame = d.frames.size() - 1;
  const registration::PointCloud source = buildSource(*d.frames[frame].deskewed, data.params, SourceOptions{});
  AugmentedTargetOptions to;
  to.num_threads = 2;
  const auto box = buildAugmentedTarget(d, frame, source, data.params, to);
  to.near_poses = {d.T_mapping_calib_guess, truth};
  to.near_radius = nearTargetRadius(data.params);
  const auto near = buildAugmentedTarget(d, frame, source, data.params, to);
  EXPECT_LT(double(near.target->size()), 0.85 * double(box.target->size()));
  const double d_eval = data.params.calibration_eval_max_corr_distance;
  for (const Pose& T : {truth, d.T_mapping_calib_guess}) {
    const auto a = scoreFrame(*box.target, source, T, d_eval, 2);
    const auto b = scoreFrame(*near.target, source, T, d_eval, 2);
    EXPECT_EQ(a.inliers, b.inliers);
    EXPECT_NEAR(a.value, b.value, 1e-9 * a.value);
  }
  // What a coarse registration at max_corr_dist_coarse from the truth sees: the same correspondences.
  const double coarse = data.params.max_corr_dist_coarse;
  EXPECT_EQ(scoreFrame(*box.target, source, truth, coarse, 2).inliers,
            scoreFrame(*near.target, source, truth, coarse, 2).inliers);
  test::releaseFlatParkingLot();
}

}  // namespace
}  // namespace rigcal::calib

namespace rigcal::calib {
namespace {

// A trajectory of keyframes with ordinary stored frames between them (keyframe_index -1), one cloud each.
pipeline::CalibrationDataset keyframesWithFramesBetween(int keyframes, int frames_between) {
  pipeline::CalibrationDataset d;
  std::uint64_t sequence = 0;
  for (int k = 0; k < keyframes; ++k) {
    for (int j = 0; j <= frames_between; ++j) {
      pipeline::MappingFrame f;
      f.sequence = sequence++;
      f.kind = j == 0 ? pipeline::FrameKind::kKeyframe : pipeline::FrameKind::kFrame;
      f.keyframe_index = j == 0 ? k : -1;
      d.trajectory.push_back(f);
      d.mapping_clouds.push_back({f, std::make_shared<const Scan>()});
    }
  }
  return d;
}

// The window of a keyframe ±n keyframes reaches back to the start when there are fewer keyframes before it;
// one keyframe short (lo = -1) it had come out empty: every frame between keyframes has keyframe_index -1
// (the parking-lot demo's most informative front_left frame was skipped as "0 points from 0 mapping clouds").
TEST(TargetWindow, AWindowReachingBeforeTheFirstKeyframeStartsAtTheFirstCloud) {
  config::Parameters params;
  params.dense_pointcloud_num_keyframes = 3;
  const int between = 2;
  pipeline::CalibrationDataset d = keyframesWithFramesBetween(10, between);
  for (int k = 0; k < 10; ++k) {
    pipeline::CalibrationFrame frame;
    frame.pairing.keyframe_frame = std::size_t(k * (between + 1));
    d.frames.push_back(frame);
  }
  for (int k = 0; k < 10; ++k) {
    const std::vector<std::size_t> window = targetWindow(d, std::size_t(k), params, 0);
    // From keyframe k-3 (or the first cloud) to keyframe k+3 (or the last cloud), every cloud between.
    const std::size_t first = std::size_t(std::max(0, k - 3) * (between + 1));
    const std::size_t last = k + 3 <= 9 ? std::size_t((k + 3) * (between + 1)) : d.mapping_clouds.size() - 1;
    ASSERT_FALSE(window.empty()) << "keyframe " << k;
    EXPECT_EQ(window.front(), first) << "keyframe " << k;
    EXPECT_EQ(window.back(), last) << "keyframe " << k;
    EXPECT_EQ(window.size(), last - first + 1) << "keyframe " << k;
  }
}

}  // namespace
}  // namespace rigcal::calib

namespace rigcal::calib {
namespace {

// The pipeline hands over only the clouds each selected frame's target is built from (its `window`),
// not every stored frame of its keyframe's ±N window: the target of each frame is made of the same
// clouds as from the whole windows, although another frame's picks now lie within its sequence range.
TEST(TargetWindow, AFramesPipelinePickedWindowGivesTheSameCloudsAsItsWholeWindow) {
  config::Parameters params;
  params.dense_pointcloud_num_keyframes = 3;
  const int between = 9;
  const pipeline::CalibrationDataset whole = keyframesWithFramesBetween(12, between);
  pipeline::CalibrationDataset picked = whole;
  picked.mapping_clouds.clear();
  std::map<std::uint64_t, std::size_t> position;  // sequence → index in picked.mapping_clouds
  std::vector<std::vector<std::uint64_t>> expected;
  pipeline::CalibrationDataset with_frames = whole;
  for (const int k : {4, 6}) {  // overlapping windows (keyframes 1..7 and 3..9)
    pipeline::CalibrationFrame frame;
    frame.pairing.keyframe_frame = std::size_t(k * (between + 1));
    with_frames.frames.push_back(frame);
  }
  for (std::size_t f = 0; f < with_frames.frames.size(); ++f) {
    std::vector<std::uint64_t> sequences;
    for (const std::size_t i : targetWindow(with_frames, f, params, pipeline::kTargetWindowClouds))
      sequences.push_back(whole.mapping_clouds[i].frame.sequence);
    ASSERT_EQ(sequences.size(), pipeline::kTargetWindowClouds) << "a 61-cloud window";
    for (const std::uint64_t s : sequences) position[s] = 0;
    expected.push_back(sequences);
  }
  for (auto& [sequence, index] : position) {
    index = picked.mapping_clouds.size();
    picked.mapping_clouds.push_back(whole.mapping_clouds[std::size_t(sequence)]);
  }
  for (std::size_t f = 0; f < with_frames.frames.size(); ++f) {
    pipeline::CalibrationFrame frame = with_frames.frames[f];
    for (const std::uint64_t s : expected[f]) frame.window.push_back(position.at(s));
    picked.frames.push_back(frame);
  }
  ASSERT_LT(picked.mapping_clouds.size(), 2 * pipeline::kTargetWindowClouds) << "the windows share picks";
  for (std::size_t f = 0; f < picked.frames.size(); ++f) {
    std::vector<std::uint64_t> sequences;
    for (const std::size_t i : targetWindow(picked, f, params, pipeline::kTargetWindowClouds))
      sequences.push_back(picked.mapping_clouds[i].frame.sequence);
    EXPECT_EQ(sequences, expected[f]) << "frame " << f;
    // A deadline that allows fewer clouds spreads them over the frame's picks, its keyframe's among them.
    const auto fewer = targetWindow(picked, f, params, 4);
    ASSERT_EQ(fewer.size(), 4u);
    const std::uint64_t own = picked.trajectory[picked.frames[f].pairing.keyframe_frame].sequence;
    EXPECT_TRUE(std::any_of(fewer.begin(), fewer.end(), [&](std::size_t i) { return picked.mapping_clouds[i].frame.sequence == own; }));
  }
}

}  // namespace
}  // namespace rigcal::calib
