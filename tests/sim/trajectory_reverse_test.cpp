// Reversing in the simulator's drive: negative speed moves base_link backwards along its −x axis without
// slip, a turn's heading follows the steering backwards, the gear changes only at rest, and stops hold.
#include <gtest/gtest.h>

#include <cmath>
#include <stdexcept>

#include "rigcal/sim/trajectory.hpp"

namespace rigcal::sim {
namespace {

using Kind = TrajectorySegment::Kind;

// Forward 3 s to 2 m/s, stop, back up to −1.5 m/s, a reversing turn of +40° heading, stop, forward again.
TrajectorySpec forwardStopReverse(double slip_deg_per_g = 0.0) {
  TrajectorySpec s;
  s.base_link_on_rear_axle = true;
  s.side_slip_rad_per_g = deg2rad(slip_deg_per_g);
  s.segments = {{Kind::kAccelerate, 3.0, 2.0, 0.0},  {Kind::kAccelerate, 2.0, 0.0, 0.0},
                {Kind::kStop, 1.0, std::nullopt, 0.0}, {Kind::kAccelerate, 2.0, -1.5, 0.0},
                {Kind::kTurn, 5.0, std::nullopt, deg2rad(40.0)}, {Kind::kAccelerate, 2.0, 0.0, 0.0},
                {Kind::kStop, 1.0, std::nullopt, 0.0}, {Kind::kAccelerate, 2.0, 1.0, 0.0}};
  return s;
}

// base_link's velocity in its own frame at t seconds, from positions 1 ms apart.
Eigen::Vector3d bodyVelocity(const Trajectory& t, double s) {
  const Pose a = t.pose(fromSeconds(s - 5e-4)), b = t.pose(fromSeconds(s + 5e-4));
  return t.pose(fromSeconds(s)).linear().transpose() * (b.translation() - a.translation()) / 1e-3;
}

TEST(TrajectoryReverse, BacksUpAlongMinusXWithoutSlip) {
  const Trajectory t(forwardStopReverse(), Ground());
  int checked = 0;
  for (double s = 6.2; s < 14.8; s += 0.2) {  // the reversing stretch, straight and turning
    const Eigen::Vector3d v = bodyVelocity(t, s);
    ASSERT_LT(t.speed(s), 0.0) << s;
    EXPECT_NEAR(v.x(), t.speed(s), 1e-3) << "backwards along −x at " << s;
    EXPECT_NEAR(v.y(), 0.0, 1e-4 * std::abs(v.x()) + 1e-6) << "no side slip at " << s;
    ++checked;
  }
  EXPECT_GT(checked, 40);
  // Forward again at the end.
  EXPECT_GT(bodyVelocity(t, 17.5).x(), 0.5);
}

TEST(TrajectoryReverse, ReversingTurnFollowsTheSteeringBackwards) {
  const Trajectory t(forwardStopReverse(), Ground());
  // The turn's heading change is +40° (nose to the left): backing up, the wheels point right, so the
  // tail swings to the right of the start line (−y) and the path curvature dh/ds is negative.
  const Pose before = t.pose(fromSeconds(8.0)), after = t.pose(fromSeconds(13.0));
  EXPECT_NEAR(toXyzRpy(after).yaw - toXyzRpy(before).yaw, deg2rad(40.0), 1e-6);
  const Eigen::Vector3d moved = before.linear().transpose() * (after.translation() - before.translation());
  EXPECT_LT(moved.x(), -3.0) << "backwards";
  EXPECT_LT(moved.y(), -0.5) << "tail to the right";
  const double s = 10.5, dt = 1e-3;
  const double yaw_rate = (t.heading(s + dt) - t.heading(s - dt)) / (2 * dt);
  EXPECT_GT(yaw_rate, 0.0);
  EXPECT_LT(yaw_rate / t.speed(s), 0.0) << "curvature dh/ds";
}

TEST(TrajectoryReverse, StopsHoldAndLengthsCountBothDirections) {
  const Trajectory t(forwardStopReverse(), Ground());
  for (const auto& [s0, s1] : {std::pair{5.0, 6.0}, std::pair{15.0, 16.0}}) {
    const Pose a = t.pose(fromSeconds(s0)), b = t.pose(fromSeconds(s1));
    EXPECT_LT((a.translation() - b.translation()).norm(), 1e-9) << s0;
    EXPECT_LT(rotationAngleBetween(a, b), 1e-12) << s0;
    EXPECT_EQ(t.speed(0.5 * (s0 + s1)), 0.0);
  }
  // Smoothstep blends travel the mean speed: forward 3 + 2 + 1 m, backwards 1.5 + 7.5 + 1.5 m.
  EXPECT_NEAR(t.reversedLength(), 10.5, 1e-9);
  EXPECT_NEAR(t.length(), 6.0 + 10.5, 1e-9);
  // The path itself agrees: the arc driven backwards, summed from positions.
  double backwards = 0;
  for (double s = 6.0; s < 16.0; s += 0.01)
    backwards += (t.pose(fromSeconds(s + 0.01)).translation() - t.pose(fromSeconds(s)).translation()).norm();
  EXPECT_NEAR(backwards, 10.5, 0.01);
}

TEST(TrajectoryReverse, SideSlipStaysOutwardBackwards) {
  const Trajectory t(forwardStopReverse(3.0), Ground());
  const double s = 10.5, dt = 1e-3;
  const double kappa = (t.heading(s + dt) - t.heading(s - dt)) / (2 * dt) / t.speed(s);
  const Eigen::Vector3d v = bodyVelocity(t, s);
  // The turn's centre is on the body's left for κ > 0: outward is −sign(κ)·y, |v_y| = slip·|v|·v²|κ|/g.
  const double want = -deg2rad(3.0) * std::abs(t.speed(s)) * t.speed(s) * t.speed(s) * kappa / 9.81;
  EXPECT_NEAR(v.y(), want, 0.05 * std::abs(want));
  EXPECT_LT(v.y() * kappa, 0.0);
}

TEST(TrajectoryReverse, ChangingDirectionWithoutStoppingIsRejected) {
  TrajectorySpec s;
  s.start_speed_mps = 2.0;
  s.segments = {{Kind::kCruise, 1.0, std::nullopt, 0.0}, {Kind::kAccelerate, 2.0, -1.0, 0.0}};
  try {
    const Trajectory t(s, Ground());
    FAIL() << "accepted a segment from +2 to −1 m/s";
  } catch (const std::invalid_argument& e) {
    EXPECT_NE(std::string(e.what()).find("segment 2 (accelerate)"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("without stopping"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace rigcal::sim
