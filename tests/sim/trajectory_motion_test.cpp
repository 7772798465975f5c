// The trajectory's kinematics that base_link_from_motion relies on: base_link's origin moves along its x
// axis, on the rear axle when asked (the wheels' contact), and side slip turns the velocity outward.
#include <gtest/gtest.h>

#include <cmath>

#include "rigcal/sim/trajectory.hpp"

namespace rigcal::sim {
namespace {

TrajectorySpec turning(double slip_deg_per_g, bool rear_axle) {
  TrajectorySpec s;
  s.start_speed_mps = 4.0;
  s.segments = {{TrajectorySegment::Kind::kCruise, 2.0, std::nullopt, 0.0},
                {TrajectorySegment::Kind::kTurn, 6.0, std::nullopt, deg2rad(90.0)}};
  s.side_slip_rad_per_g = deg2rad(slip_deg_per_g);
  s.base_link_on_rear_axle = rear_axle;
  return s;
}

// The angle between base_link's velocity (from positions 1 ms apart) and its x axis, at t seconds.
double slipAngle(const Trajectory& t, double s) {
  const Pose a = t.pose(fromSeconds(s - 5e-4)), b = t.pose(fromSeconds(s + 5e-4));
  const Eigen::Vector3d v = t.pose(fromSeconds(s)).linear().transpose() * (b.translation() - a.translation());
  return std::atan2(v.y(), v.x());
}

TEST(TrajectoryMotion, BaseLinkMovesAlongItsAxisWithoutSlip) {
  const Trajectory t(turning(0.0, false), Ground());
  for (double s : {1.0, 3.0, 5.0, 7.0}) EXPECT_NEAR(slipAngle(t, s), 0.0, 1e-4) << s;
}

TEST(TrajectoryMotion, SideSlipTurnsTheVelocityOutwardByLateralAcceleration) {
  const Trajectory t(turning(3.0, false), Ground());
  // Mid-turn: raised-cosine curvature peaks at twice the mean, κ = 2·(π/2)/(4 m/s · 6 s).
  const double kappa = 2 * (M_PI / 2) / (4.0 * 6.0);
  const double want = -deg2rad(3.0) * 4.0 * 4.0 * kappa / 9.81;
  EXPECT_NEAR(slipAngle(t, 5.0), want, 0.05 * std::abs(want));
  EXPECT_NEAR(slipAngle(t, 1.0), 0.0, 1e-4);  // straight: no slip
}

TEST(TrajectoryMotion, RearAxleBaseLinkSitsOnTheRearWheelsGround) {
  GroundSpec g;
  g.slope = {0.1, 0.0};
  g.bump_amplitude = 0.0;
  const Ground ground(g, 0);
  const Trajectory centre(turning(0.0, false), ground), rear(turning(0.0, true), ground);
  // Same path; the body's height at base_link is the ground's under it in both cases (a plane slope).
  const Pose a = centre.pose(fromSeconds(1.0)), b = rear.pose(fromSeconds(1.0));
  EXPECT_NEAR((a.translation() - b.translation()).head<2>().norm(), 0.0, 1e-9);
  EXPECT_NEAR(a.translation().z(), ground.height(a.translation().x(), a.translation().y()), 1e-6);
  EXPECT_NEAR(b.translation().z(), ground.height(b.translation().x(), b.translation().y()), 1e-6);
  EXPECT_NEAR(toXyzRpy(a).pitch, toXyzRpy(b).pitch, 1e-9);
}

}  // namespace
}  // namespace rigcal::sim
