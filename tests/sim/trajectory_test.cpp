#include <gtest/gtest.h>

#include <cmath>

#include "rigcal/sim/simulation.hpp"

namespace rigcal::sim {
namespace {

constexpr double kKmh = 1 / 3.6;

Eigen::Vector3d positionAt(const Trajectory& t, double s) { return t.pose(fromSeconds(s)).translation(); }

// Segments of a given kind, as [start, end) in seconds.
std::vector<std::pair<double, double>> segmentsOf(const Trajectory& t, TrajectorySegment::Kind kind) {
  std::vector<std::pair<double, double>> out;
  for (std::size_t i = 0; i < t.spec().segments.size(); ++i)
    if (t.spec().segments[i].kind == kind)
      out.emplace_back(t.segmentStart(i), t.segmentStart(i) + t.spec().segments[i].duration_s);
  return out;
}

TEST(Trajectory, ParkingLotCruisesNearFiveKmhAndStopsForSeconds) {
  const Simulation sim(loadScenario("parking-lot"));
  const Trajectory& t = sim.trajectory();
  EXPECT_NEAR(toSeconds(t.duration()), 40.0, 5.0);
  const auto cruises = segmentsOf(t, TrajectorySegment::Kind::kCruise);
  ASSERT_FALSE(cruises.empty());
  // Measured from positions, not the profile: distance over a second of cruise.
  const auto [c0, c1] = cruises.front();
  const double measured = (positionAt(t, c0 + 1.5) - positionAt(t, c0 + 0.5)).head<2>().norm();
  EXPECT_NEAR(measured, 5 * kKmh, 0.02);
  const auto stops = segmentsOf(t, TrajectorySegment::Kind::kStop);
  double longest = 0;
  for (const auto& [s0, s1] : stops) {
    longest = std::max(longest, s1 - s0);
    const Pose a = t.pose(fromSeconds(s0)), b = t.pose(fromSeconds(s1));
    EXPECT_LT((a.translation() - b.translation()).norm(), 1e-9) << "stopped means not moving at all";
    EXPECT_LT(rotationAngleBetween(a, b), 1e-12);
  }
  EXPECT_GE(longest, 3.0) << "at least one full stop of several seconds";
  // A fast segment exists: somewhere the speed exceeds 10 km/h.
  double vmax = 0;
  for (double s = 0; s < toSeconds(t.duration()); s += 0.05) vmax = std::max(vmax, t.speed(s));
  EXPECT_GT(vmax, 10 * kKmh);
}

TEST(Trajectory, PositionAndVelocityAreContinuous) {
  const Simulation sim(loadScenario("parking-lot"));
  const Trajectory& t = sim.trajectory();
  const double dt = 1e-3, end = toSeconds(t.duration());
  Eigen::Vector3d prev_v = Eigen::Vector3d::Zero();
  double worst_jump = 0, worst_dv = 0;
  for (double s = dt; s + dt < end; s += dt) {
    const Eigen::Vector3d p0 = positionAt(t, s - dt), p1 = positionAt(t, s), p2 = positionAt(t, s + dt);
    const Eigen::Vector3d v = (p2 - p0) / (2 * dt);
    worst_jump = std::max(worst_jump, (p1 - p0).norm());
    if (s > 2 * dt) worst_dv = std::max(worst_dv, (v - prev_v).norm());
    prev_v = v;
    // The planar velocity matches the speed profile along the heading.
    const double h = t.heading(s);
    EXPECT_NEAR(v.x() * std::cos(h) + v.y() * std::sin(h), t.speed(s), 0.01) << "at " << s;
  }
  // At ≤ 12 km/h a millisecond moves ≤ 3.4 mm; a velocity step would show as a jump of dv.
  EXPECT_LT(worst_jump, 0.004);
  EXPECT_LT(worst_dv, 0.05);
}

TEST(Trajectory, VehicleRestsOnTheGround) {
  const Simulation sim(loadScenario("parking-lot"));
  const Trajectory& t = sim.trajectory();
  const Ground& g = sim.scene().ground();
  for (double s = 0; s < toSeconds(t.duration()); s += 0.5) {
    const Pose T = t.pose(fromSeconds(s));
    const Eigen::Vector3d p = T.translation();
    // Averaged over the wheels: within the bump amplitude of the ground under the centre.
    EXPECT_NEAR(p.z(), g.height(p.x(), p.y()), 0.05);
    // Up follows the ground normal (slope 1.2 %, bumps) to within a degree.
    EXPECT_LT(std::acos(std::min(1.0, T.linear().col(2).dot(g.normal(p.x(), p.y())))), deg2rad(1.5));
  }
}

TEST(Trajectory, LostScenarioJerkExceedsTheMapperThreshold) {
  const Simulation sim(loadScenario("lost"));
  const Trajectory& t = sim.trajectory();
  const auto jerks = segmentsOf(t, TrajectorySegment::Kind::kJerk);
  ASSERT_EQ(jerks.size(), 1u);
  double peak = 0;
  for (double s = jerks[0].first; s < jerks[0].second; s += 1e-3) peak = std::max(peak, std::abs(t.acceleration(s)));
  EXPECT_GT(peak, 8.0);
  // As the mapper sees it: |Δ rough speed| / dt between 10 Hz frames, from positions.
  double worst = 0;
  for (double s = jerks[0].first - 0.3; s < jerks[0].second + 0.3; s += 0.01) {
    const double v0 = (positionAt(t, s) - positionAt(t, s - 0.1)).norm() / 0.1;
    const double v1 = (positionAt(t, s + 0.1) - positionAt(t, s)).norm() / 0.1;
    worst = std::max(worst, std::abs(v1 - v0) / 0.1);
  }
  EXPECT_GT(worst, 8.0) << "lost_frame_max_acceleration must be exceeded";
  // And the mapping lidar goes silent for longer than mapping_lost_timeout (1 s).
  const auto& top = sim.scenario().sensors[sim.scenario().sensorIndex("top")];
  ASSERT_EQ(top.outages.size(), 1u);
  EXPECT_GT(top.outages[0].to_s - top.outages[0].from_s, 1.0);
}

TEST(Trajectory, PoseScenarioExcitesRollAndPitch) {
  const Scenario sc = loadScenario("pose");
  const Simulation sim(sc);
  const Trajectory& t = sim.trajectory();
  // Roll/pitch relative to the ground-following attitude: the excitation alone.
  TrajectorySpec flat_spec = sc.trajectory;
  flat_spec.excitation = {};
  const Trajectory plain(flat_spec, makeGround(sc.scene, sim.sceneSeed()));
  double roll_lo = 1, roll_hi = -1, pitch_lo = 1, pitch_hi = -1;
  for (double s = 0; s < toSeconds(t.duration()); s += 0.01) {
    const XyzRpy a = toXyzRpy(t.pose(fromSeconds(s))), b = toXyzRpy(plain.pose(fromSeconds(s)));
    roll_lo = std::min(roll_lo, a.roll - b.roll);
    roll_hi = std::max(roll_hi, a.roll - b.roll);
    pitch_lo = std::min(pitch_lo, a.pitch - b.pitch);
    pitch_hi = std::max(pitch_hi, a.pitch - b.pitch);
  }
  const Excitation& e = sc.trajectory.excitation;
  EXPECT_NEAR(0.5 * (roll_hi - roll_lo), e.roll_amplitude_rad, deg2rad(0.2));
  EXPECT_NEAR(0.5 * (pitch_hi - pitch_lo), e.pitch_amplitude_rad, deg2rad(0.2));
  EXPECT_GE(rad2deg(e.roll_amplitude_rad), 3.0);
  EXPECT_GE(rad2deg(e.pitch_amplitude_rad), 3.0);
}

TEST(Trajectory, RejectsImpossibleSegments) {
  TrajectorySpec spec;
  spec.start_speed_mps = 1.0;
  spec.segments = {{TrajectorySegment::Kind::kStop, 2.0, std::nullopt, 0.0}};
  EXPECT_THROW(Trajectory(spec, Ground()), std::invalid_argument) << "stop while moving";
  spec.start_speed_mps = 0;
  spec.segments = {{TrajectorySegment::Kind::kTurn, 2.0, std::nullopt, 1.0}};
  EXPECT_THROW(Trajectory(spec, Ground()), std::invalid_argument) << "turn at rest";
}

}  // namespace
}  // namespace rigcal::sim
