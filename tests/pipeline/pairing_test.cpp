#include <gtest/gtest.h>

#include "rigcal/pipeline/frame_tracker.hpp"
#include "rigcal/pipeline/pairing.hpp"

namespace rigcal::pipeline {
namespace {

constexpr TimeNs kFramePeriod = 100 * kNsPerMs;

// Frames along x with position x(t) given by `motion`, one every 100 ms.
std::vector<MappingFrame> track(double (*motion)(double), int n, double yaw_rate = 0) {
  FrameTracker tracker{config::Parameters{}};
  for (int i = 0; i < n; ++i) {
    const double t = 0.1 * i;
    tracker.add(i, i * kFramePeriod, fromXyzRpy({motion(t), 0, 0, 0, 0, yaw_rate * t}), true);
  }
  return tracker.frames();
}

TEST(Pairing, ConstantVelocityIsAccepted) {
  const auto frames = track([](double t) { return 1.2 * t; }, 30);
  const auto p = pairKeyframe(frames, 10, 7, 10 * kFramePeriod + 30 * kNsPerMs, config::Parameters{});
  ASSERT_TRUE(p);
  EXPECT_NEAR(p->stats.time_s, 0.03, 1e-12);
  EXPECT_NEAR(p->stats.speed, 1.2, 1e-9);
  EXPECT_NEAR(p->stats.accel, 0.0, 1e-9);
  EXPECT_NEAR(p->stats.distance_m, 1.2 * 0.03, 1e-9);
  EXPECT_NEAR(p->T_map_mapping_at_scan.translation().x(), 1.2 * 1.03, 1e-9);
  EXPECT_TRUE(p->standard_ok);
  EXPECT_TRUE(p->accepted) << p->rejection;
}

TEST(Pairing, AccelerationUsesTheFactorTwo) {
  // x = t² → a = 2 m/s²; the second difference over three frames gives exactly 2.
  const auto frames = track([](double t) { return t * t; }, 30);
  const auto p = pairKeyframe(frames, 10, 0, 10 * kFramePeriod + 10 * kNsPerMs, config::Parameters{});
  ASSERT_TRUE(p);
  EXPECT_NEAR(p->stats.accel, 2.0, 1e-6);
  EXPECT_FALSE(p->accepted);
  EXPECT_NE(p->rejection.find("accel"), std::string::npos) << p->rejection;
}

TEST(Pairing, RotationAndTimeGapAreMeasured) {
  const auto frames = track([](double t) { return 0.6 * t; }, 30, 0.2);  // 0.2 rad/s yaw
  const auto p = pairKeyframe(frames, 10, 0, 10 * kFramePeriod + 60 * kNsPerMs, config::Parameters{});
  ASSERT_TRUE(p);
  EXPECT_NEAR(p->stats.angle_deg, rad2deg(0.2 * 0.06), 1e-6);
  EXPECT_FALSE(p->accepted) << "0.06 s exceeds max_allowed_interpolated_time";
}

TEST(Pairing, WaitsForTheFramesAfterTheScan) {
  const auto frames = track([](double t) { return t; }, 12);
  EXPECT_FALSE(pairKeyframe(frames, 10, 0, 11 * kFramePeriod + kNsPerMs, config::Parameters{}).has_value());
  EXPECT_FALSE(pairKeyframe(frames, 0, 0, -kNsPerMs, config::Parameters{}).has_value());
}

TEST(Pairing, OnlyStoppedWhenAsked) {
  config::Parameters params;
  params.calibration_use_only_stopped = true;
  const auto frames = track([](double t) { return t; }, 30);
  const auto p = pairKeyframe(frames, 10, 0, 10 * kFramePeriod, params);
  ASSERT_TRUE(p);
  EXPECT_FALSE(p->accepted);
}

}  // namespace
}  // namespace rigcal::pipeline
