#include "rigcal/registration/evaluator.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "scenes.hpp"

namespace rigcal::registration {
namespace {

TEST(Evaluator, PerfectOverlapShiftAndNoOverlap) {
  const PointCloud cloud = test::room(0.2);
  const Target target(cloud);
  const Evaluation same = evaluate(target, cloud, Pose::Identity(), 0.1);
  EXPECT_EQ(same.points, cloud.size());
  EXPECT_EQ(same.inliers, cloud.size());
  EXPECT_NEAR(same.rmse, 0.0, 1e-12);
  EXPECT_EQ(same.inlier_ratio, 1.0);
  EXPECT_NEAR(same.fitness, 0.0, 1e-12);

  // A 5 cm shift along x: wall points off by 5 cm, floor points too (their neighbour is 5 cm away).
  Pose shift = Pose::Identity();
  shift.translation().x() = 0.05;
  const Evaluation shifted = evaluate(target, cloud, shift, 0.1, 2);
  EXPECT_GT(shifted.inlier_ratio, 0.99);
  EXPECT_GT(shifted.rmse, 0.01);
  EXPECT_LE(shifted.rmse, 0.05 + 1e-9);
  EXPECT_GT(shifted.fitness, same.fitness);

  // Nothing corresponds: well defined, the worst possible values, no NaN.
  Pose away = Pose::Identity();
  away.translation().z() = 100.0;
  const Evaluation none = evaluate(target, cloud, away, 0.1);
  EXPECT_EQ(none.inliers, 0u);
  EXPECT_EQ(none.inlier_ratio, 0.0);
  EXPECT_DOUBLE_EQ(none.rmse, 0.1);
  EXPECT_DOUBLE_EQ(none.mean_sq_distance, 0.01);
  EXPECT_DOUBLE_EQ(none.fitness, 0.01);

  const Evaluation empty = evaluate(target, PointCloud{}, Pose::Identity(), 0.1);
  EXPECT_EQ(empty.points, 0u);
  EXPECT_FALSE(std::isnan(empty.rmse) || std::isnan(empty.fitness) || std::isnan(empty.inlier_ratio));

  EXPECT_THROW(evaluate(target, cloud, Pose::Identity(), 0.0), std::invalid_argument);
}

TEST(Evaluator, PairsCountAsOneCloud) {
  const PointCloud a = test::room(0.25), b = test::corridor(0.25);
  const Target ta(a), tb(b);
  const SourceTarget pairs[] = {{&a, &ta}, {&b, &tb}};
  const Evaluation e = evaluate(pairs, Pose::Identity(), 0.05);
  EXPECT_EQ(e.points, a.size() + b.size());
  EXPECT_EQ(e.inliers, a.size() + b.size());
}

}  // namespace
}  // namespace rigcal::registration
