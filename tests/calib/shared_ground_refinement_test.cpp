// SharedGroundReference on a synthetic bay where the answer is known exactly: a hall (floor, four walls,
// two pillars) with a wide platform 0.75 m above the floor, seen by a level "roof" lidar that sees the
// floor only beyond 6.5 m (the platform has more points than that floor) and by a tilted side lidar.
//  - from the truth moved 0.4° in tilt, 1 cm and 0.1° in yaw, the refinement returns to the truth (measured
//    0.002°, 0.5 mm: what the 5 cm structure voxels leave);
//  - the platform is not taken for the floor (its plane has floor under it);
//  - without the floor in the source (only the platform under it), nothing is applied and the pose comes
//    back unchanged.
#include <gtest/gtest.h>

#include <cmath>
#include <functional>
#include <vector>

#include <Eigen/Geometry>

#include "rigcal/calib/lidar_lidar/shared_ground_refinement.hpp"

namespace rigcal::calib {
namespace {

constexpr double kFloorZ = -1.95;  // the floor in the roof lidar's frame

struct WorldPoint {
  Eigen::Vector3d p;
  bool floor = false;
};

// The hall in the roof lidar's frame, sampled on regular grids.
std::vector<WorldPoint> hall() {
  std::vector<WorldPoint> w;
  const auto grid = [&](double a0, double a1, double b0, double b1, double step,
                        const std::function<Eigen::Vector3d(double, double)>& at, bool floor) {
    for (double a = a0; a <= a1 + 1e-9; a += step)
      for (double b = b0; b <= b1 + 1e-9; b += step) w.push_back({at(a, b), floor});
  };
  grid(-10, 10, -8, 8, 0.1, [](double x, double y) { return Eigen::Vector3d(x, y, kFloorZ); }, true);
  for (const double x : {-10.0, 10.0})
    grid(-8, 8, kFloorZ, 2.0, 0.1, [x](double y, double z) { return Eigen::Vector3d(x, y, z); }, false);
  for (const double y : {-8.0, 8.0})
    grid(-10, 10, kFloorZ, 2.0, 0.1, [y](double x, double z) { return Eigen::Vector3d(x, y, z); }, false);
  // A platform 0.75 m above the floor on a fine grid (more points than the floor the roof lidar sees),
  // with its front face.
  grid(2, 5, -3, 3, 0.03, [](double x, double y) { return Eigen::Vector3d(x, y, kFloorZ + 0.75); }, false);
  grid(-3, 3, kFloorZ, kFloorZ + 0.75, 0.05, [](double y, double z) { return Eigen::Vector3d(2, y, z); }, false);
  // Two pillars (0.4 m square), so yaw and both translations are fixed by more than the walls.
  for (const Eigen::Vector2d& c : {Eigen::Vector2d(-4, 5), Eigen::Vector2d(6, -5)}) {
    for (const double s : {-0.2, 0.2}) {
      grid(-0.2, 0.2, kFloorZ, 2.0, 0.05, [&](double a, double z) { return Eigen::Vector3d(c.x() + s, c.y() + a, z); }, false);
      grid(-0.2, 0.2, kFloorZ, 2.0, 0.05, [&](double a, double z) { return Eigen::Vector3d(c.x() + a, c.y() + s, z); }, false);
    }
  }
  return w;
}

Scan scanOf(const std::vector<WorldPoint>& world, const Pose& T_roof_sensor,
            const std::function<bool(const WorldPoint&, const Eigen::Vector3d&)>& sees) {
  Scan s;
  const Pose T_sensor_roof = T_roof_sensor.inverse();
  for (const auto& w : world) {
    const Eigen::Vector3d q = T_sensor_roof * w.p;
    if (!sees(w, q)) continue;
    s.x.push_back(float(q.x()));
    s.y.push_back(float(q.y()));
    s.z.push_back(float(q.z()));
  }
  return s;
}

const Pose kTruth = fromXyzRpy({0.5, 0.95, -0.55, deg2rad(-35), deg2rad(20), deg2rad(80)});

// The roof lidar: floor only from 6.5 m out (its lowest beam), everything else within 12 m.
Scan roofScan(const std::vector<WorldPoint>& world) {
  return scanOf(world, Pose::Identity(), [](const WorldPoint& w, const Eigen::Vector3d& q) {
    const double horizontal = q.head<2>().norm();
    return w.floor ? horizontal > 6.5 : q.norm() < 12.0;
  });
}

// The side lidar: what lies within 9 m of it, floor included (`with_floor` false: none of the floor).
Scan sideScan(const std::vector<WorldPoint>& world, bool with_floor) {
  return scanOf(world, kTruth, [with_floor](const WorldPoint& w, const Eigen::Vector3d& q) {
    return (with_floor || !w.floor) && q.norm() < 9.0;
  });
}

TEST(SharedGroundReference, ReturnsToTheTruthFromTiltHeightAndYawErrors) {
  const auto world = hall();
  const SharedGroundReference reference(roofScan(world), Eigen::Vector3d::UnitZ());
  ASSERT_TRUE(reference.ok());
  // Off by 0.4° about a horizontal axis (the weak tilt), 1 cm mostly up, 0.1° in yaw.
  const Pose off = Pose(Eigen::AngleAxisd(deg2rad(0.4), Eigen::Vector3d(1, 1, 0).normalized())) *
                   Pose(Eigen::AngleAxisd(deg2rad(0.1), Eigen::Vector3d::UnitZ()));
  Pose start = off * kTruth;
  start.translation() = kTruth.translation() + Eigen::Vector3d(0.004, -0.003, 0.008);
  const auto r = reference.refine(sideScan(world, true), start);
  ASSERT_TRUE(r.applied) << r.note;
  const double cm = 100 * (r.T_target_source.translation() - kTruth.translation()).norm();
  const double deg = rad2deg(rotationAngleBetween(r.T_target_source, kTruth));
  EXPECT_LT(cm, 0.1) << "start was " << 100 * (start.translation() - kTruth.translation()).norm() << " cm";
  EXPECT_LT(deg, 0.005) << "start was " << rad2deg(rotationAngleBetween(start, kTruth)) << " deg";
  EXPECT_NEAR(r.tilt_correction_deg, 0.4, 0.02);
  // The floor found under the roof lidar is the floor, not the platform 0.75 m above it.
  EXPECT_NEAR(r.floor_normal.z(), 1.0, 1e-6);
  EXPECT_GT(r.target_floor_points, 1000u);
}

TEST(SharedGroundReference, WithoutFloorUnderTheSourceNothingIsApplied) {
  const auto world = hall();
  const SharedGroundReference reference(roofScan(world), Eigen::Vector3d::UnitZ());
  ASSERT_TRUE(reference.ok());
  Pose start = kTruth;
  start.translation().z() += 0.02;
  const auto r = reference.refine(sideScan(world, false), start);
  EXPECT_FALSE(r.applied) << "the platform 0.65 m under the side lidar was taken for the floor";
  EXPECT_FALSE(r.note.empty());
  EXPECT_TRUE(r.T_target_source.isApprox(start));
}

}  // namespace
}  // namespace rigcal::calib
