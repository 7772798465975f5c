#include <gtest/gtest.h>

#include "rigcal/pipeline/deskew.hpp"

namespace rigcal::pipeline {
namespace {

// A sensor moving at 2 m/s along x and turning at 0.5 rad/s sweeps a wall; each point is recorded in
// the sensor frame of its own firing time. Deskew must put them back into the frame at the stamp.
TEST(Deskew, ConstantVelocityRestoresTheStaticWorld) {
  const TimeNs dt = 100 * kNsPerMs;
  const Pose motion = fromXyzRpy({0.2, 0, 0, 0, 0, 0.05});  // per 100 ms
  const SensorMotion truth = constantVelocity(motion, dt, 0);

  Scan raw;
  raw.stamp_ns = 0;
  std::vector<Eigen::Vector3d> world;
  for (int i = 0; i < 1000; ++i) {
    const TimeNs t = i * dt / 1000;
    const Eigen::Vector3d p_ref(10.0, -5.0 + 0.01 * i, 0.5 * std::sin(0.01 * i));
    world.push_back(p_ref);
    const Eigen::Vector3d p_sensor = truth(t).inverse() * p_ref;
    raw.push_back(Point{float(p_sensor.x()), float(p_sensor.y()), float(p_sensor.z()), 0, 0, t, 0});
  }
  double raw_error = 0;
  for (std::size_t i = 0; i < raw.size(); ++i)
    raw_error = std::max(raw_error, (Eigen::Vector3d(raw.x[i], raw.y[i], raw.z[i]) - world[i]).norm());
  EXPECT_GT(raw_error, 0.3) << "the skew is real";

  deskew(raw, truth);
  for (std::size_t i = 0; i < raw.size(); ++i)
    ASSERT_LT((Eigen::Vector3d(raw.x[i], raw.y[i], raw.z[i]) - world[i]).norm(), 1e-3) << i;
}

}  // namespace
}  // namespace rigcal::pipeline
