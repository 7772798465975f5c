// Base-lidar calibration over many keyframes on the simulator's bumpy parking lot: the median of the
// per-keyframe ground fits must recover the mounting's z, roll and pitch where one keyframe cannot
// (the body rests on its wheels, so its tilt over the local ground follows the bumps).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "lidar_lidar_sim_dataset.hpp"
#include "rigcal/calib/base_lidar/base_lidar_multi.hpp"
#include "sanitizers.hpp"

namespace rigcal {
namespace {

struct Errors {
  double z = 0, roll_deg = 0, pitch_deg = 0;
};

Errors errorsOf(const Pose& estimate, const Pose& truth) {
  const XyzRpy e = toXyzRpy(estimate), t = toXyzRpy(truth);
  return {std::abs(e.z - t.z), rad2deg(std::abs(e.roll - t.roll)), rad2deg(std::abs(e.pitch - t.pitch))};
}

// Accuracy over a simulated 12 s drive (under ASan its simulation alone took 50 s per test). Under the
// sanitizers calibrateBaseLidarMulti runs in BaseLidarMulti.NoKeyframeOrNoGroundFailsWithAMessage.
constexpr const char* kReleaseOnly = "accuracy over a simulated drive: Release only";

class BaseLidarMultiTest : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (RIGCAL_SANITIZED) return;  // see kReleaseOnly
    test::SimDatasetOptions o;  // the preset's 4 cm bumps every 5 m and 1.2 % slope
    o.frames = 2;
    o.seconds = 12.0;  // under three bump periods: shorter stretches do not average them out
    data_ = std::make_unique<test::SimDatasets>(test::buildSimDatasets(o));
    const auto& d = data_->datasets.front();
    for (const auto& c : d.mapping_clouds) {
      const Scan& s = *c.cloud;
      for (std::size_t j = 0; j < s.size(); ++j)
        map_.push_back(c.frame.T_map_lidar * Eigen::Vector3d(s.x[j], s.y[j], s.z[j]));
    }
    for (const auto& f : d.trajectory)
      if (f.keyframe_index >= 0) keyframes_.push_back(f.T_map_lidar);
  }
  static void TearDownTestSuite() {
    data_.reset();
    map_.clear();
    keyframes_.clear();
  }

  static std::unique_ptr<test::SimDatasets> data_;
  static std::vector<Eigen::Vector3d> map_;
  static std::vector<Pose> keyframes_;
};

std::unique_ptr<test::SimDatasets> BaseLidarMultiTest::data_;
std::vector<Eigen::Vector3d> BaseLidarMultiTest::map_;
std::vector<Pose> BaseLidarMultiTest::keyframes_;

TEST_F(BaseLidarMultiTest, MedianOverKeyframesBeatsOneKeyframeOnBumps) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << kReleaseOnly;
  ASSERT_GE(keyframes_.size(), 6u);
  const Pose truth = data_->truth_T_base_mapping;
  const Pose guess = test::perturb(truth, 0.05, 1.0, 3);
  config::Parameters p = data_->params;
  // Upstream's ±20 m box: the lot's bumps tilt each keyframe's plane; only the median cancels them.
  p.base_lidar_crop_box_min_x = p.base_lidar_crop_box_min_y = p.base_lidar_crop_box_min_z = -20.0;
  p.base_lidar_crop_box_max_x = p.base_lidar_crop_box_max_y = p.base_lidar_crop_box_max_z = 20.0;
  calib::BaseLidarMultiSettings s;
  s.max_points_per_fit = 30000;  // keeps the test short; the command fits more

  // Every keyframe on its own: the spread the bumps cause.
  Errors worst;
  for (const auto& kf : keyframes_) {
    const auto one = calib::calibrateBaseLidarMulti(map_, {kf}, guess, p, s);
    ASSERT_TRUE(one.ok) << one.failure;
    const Errors e = errorsOf(one.T_base_lidar, truth);
    worst = {std::max(worst.z, e.z), std::max(worst.roll_deg, e.roll_deg), std::max(worst.pitch_deg, e.pitch_deg)};
  }

  const auto all = calib::calibrateBaseLidarMulti(map_, keyframes_, guess, p, s);
  ASSERT_TRUE(all.ok) << all.failure;
  EXPECT_EQ(all.keyframes_tried, std::min(keyframes_.size(), s.max_keyframes));
  EXPECT_EQ(all.keyframes_used, all.keyframes_tried);
  const Errors e = errorsOf(all.T_base_lidar, truth);
  std::printf("%zu keyframes: worst single |dz| %.4f m roll %.3f° pitch %.3f°; combined |dz| %.4f m roll %.3f° "
              "pitch %.3f°; spread z %.4f m roll %.3f° pitch %.3f°\n",
              all.keyframes_used, worst.z, worst.roll_deg, worst.pitch_deg, e.z, e.roll_deg, e.pitch_deg,
              all.spread_z, all.spread_roll_deg, all.spread_pitch_deg);
  // The issue asks 1 cm / 0.05° on the whole parking-lot drive (24 keyframes, several bump periods);
  // this 12 s stretch covers under three bump periods, so the bounds here are looser: the combined
  // estimate must halve the worst single keyframe's error and stay within 1.5 cm / 0.15°.
  EXPECT_LT(e.z, 0.015);
  EXPECT_LT(e.roll_deg, 0.15);
  EXPECT_LT(e.pitch_deg, 0.15);
  EXPECT_LT(e.z, 0.5 * worst.z);
  EXPECT_LT(std::max(e.roll_deg, e.pitch_deg), 0.5 * std::max(worst.roll_deg, worst.pitch_deg));
  EXPECT_TRUE(std::isfinite(all.spread_z) && std::isfinite(all.spread_pitch_deg));
}

// The map holds the ground under the car at each keyframe (seen before it drove there): cropping to the
// footprint fits the plane the wheels rest on, so the bumps drop out of each estimate, not only the median.
// The default crop box is the default vehicle footprint's (config/vehicle_footprint.hpp): no setting needed.
TEST_F(BaseLidarMultiTest, DefaultFootprintCropMeetsTheIssueTargets) {
  if (RIGCAL_SANITIZED) GTEST_SKIP() << kReleaseOnly;
  const Pose truth = data_->truth_T_base_mapping;
  const Pose guess = test::perturb(truth, 0.05, 1.0, 3);
  config::Parameters p = data_->params;
  const config::Parameters defaults;
  ASSERT_EQ(p.base_lidar_crop_box_max_x, defaults.base_lidar_crop_box_max_x) << "the default box is under test";
  ASSERT_LT(p.base_lidar_crop_box_max_x - p.base_lidar_crop_box_min_x, 6.0) << "a footprint, not upstream's ±20 m";
  const auto all = calib::calibrateBaseLidarMulti(map_, keyframes_, guess, p);
  ASSERT_TRUE(all.ok) << all.failure;
  const Errors e = errorsOf(all.T_base_lidar, truth);
  std::printf("footprint crop, %zu keyframes: |dz| %.4f m roll %.3f° pitch %.3f°\n", all.keyframes_used, e.z,
              e.roll_deg, e.pitch_deg);
  EXPECT_GE(all.keyframes_used, all.keyframes_tried / 2);
  EXPECT_LT(e.z, 0.01);
  EXPECT_LT(e.roll_deg, 0.05);
  EXPECT_LT(e.pitch_deg, 0.05);
}

// The failures need no drive: a flat ground around one keyframe (a simulated drive would only add setup).
TEST(BaseLidarMulti, NoKeyframeOrNoGroundFailsWithAMessage) {
  std::vector<Eigen::Vector3d> ground;
  for (double x = -10.0; x <= 10.0; x += 0.1)
    for (double y = -10.0; y <= 10.0; y += 0.1) ground.emplace_back(x, y, 0.0);
  const Pose T_map_lidar = fromXyzRpy({0.0, 0.0, 1.9, 0.0, 0.0, 0.0});
  const Pose T_base_lidar = fromXyzRpy({1.1, 0.0, 1.9, 0.0, 0.0, 0.0});
  const config::Parameters defaults;
  const auto found = calib::calibrateBaseLidarMulti(ground, {T_map_lidar}, T_base_lidar, defaults);
  ASSERT_TRUE(found.ok) << "the ground these failures take away is found: " << found.failure;

  const auto none = calib::calibrateBaseLidarMulti(ground, {}, T_base_lidar, defaults);
  EXPECT_FALSE(none.ok);
  EXPECT_NE(none.failure.find("no keyframe"), std::string::npos) << none.failure;
  config::Parameters p = defaults;
  p.base_lidar_crop_box_min_z = 50.0;  // nothing in the box
  p.base_lidar_crop_box_max_z = 60.0;
  const auto empty = calib::calibrateBaseLidarMulti(ground, {T_map_lidar}, T_base_lidar, p);
  EXPECT_FALSE(empty.ok);
  EXPECT_EQ(empty.keyframes_used, 0u);
  EXPECT_NE(empty.failure.find("no ground plane"), std::string::npos) << empty.failure;
}

}  // namespace
}  // namespace rigcal
