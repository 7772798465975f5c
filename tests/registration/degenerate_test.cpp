// Bad or degenerate input gives a clear status and a one-line reason, never a crash or a NaN pose.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <string>

#include "methods.hpp"
#include "rigcal/registration/covariance.hpp"
#include "scenes.hpp"

namespace rigcal::registration {
namespace {

using test::Method;

void expectWellFormed(const RegistrationResult& r) {
  EXPECT_TRUE(r.T_target_source.matrix().allFinite());
  EXPECT_TRUE(std::isfinite(r.rmse) && std::isfinite(r.fitness) && std::isfinite(r.inlier_ratio));
  EXPECT_FALSE(r.reason.empty());
  EXPECT_EQ(r.reason.find('\n'), std::string::npos) << r.reason;
  EXPECT_FALSE(r.ok());
}

PointCloud withCovariances(PointCloud c) {
  if (c.size() > 0) estimateCovariances(c);
  return c;
}

class Degenerate : public ::testing::TestWithParam<Method> {
 protected:
  static const Target& roomTarget() {
    static const Target target(test::room(0.25), test::fullTarget());
    return target;
  }
};

TEST_P(Degenerate, EmptySourceOrTarget) {
  const RegistrationResult r = test::run(GetParam(), roomTarget(), PointCloud{}, Pose::Identity());
  EXPECT_EQ(r.status, Status::kInvalidInput);
  EXPECT_NE(r.reason.find("source is empty"), std::string::npos) << r.reason;
  expectWellFormed(r);

  const Target empty(PointCloud{}, test::fullTarget());
  const RegistrationResult e = test::run(GetParam(), empty, withCovariances(test::room(0.5)), Pose::Identity());
  EXPECT_EQ(e.status, Status::kInvalidInput);
  EXPECT_NE(e.reason.find("target is empty"), std::string::npos) << e.reason;
  expectWellFormed(e);
}

TEST_P(Degenerate, OnePoint) {
  PointCloud one;
  one.add(0.5, 0.5, 0.23);
  const RegistrationResult r = test::run(GetParam(), roomTarget(), withCovariances(one), Pose::Identity());
  EXPECT_EQ(r.status, Status::kInvalidInput) << r.reason;  // fewer points than min_correspondences
  expectWellFormed(r);

  test::RunOptions allow;
  allow.min_correspondences = 1;
  const RegistrationResult d = test::run(GetParam(), roomTarget(), withCovariances(one), Pose::Identity(), allow);
  EXPECT_EQ(d.status, Status::kDegenerate) << d.reason;
  expectWellFormed(d);
}

TEST_P(Degenerate, NonFiniteSourceOrGuess) {
  PointCloud src = withCovariances(test::room(0.5));
  src.points[3].y() = std::numeric_limits<double>::quiet_NaN();
  const RegistrationResult r = test::run(GetParam(), roomTarget(), src, Pose::Identity());
  EXPECT_EQ(r.status, Status::kInvalidInput);
  EXPECT_NE(r.reason.find("non-finite"), std::string::npos) << r.reason;
  expectWellFormed(r);

  Pose nan_guess = Pose::Identity();
  nan_guess.translation().x() = std::numeric_limits<double>::infinity();
  const RegistrationResult g = test::run(GetParam(), roomTarget(), withCovariances(test::room(0.5)), nan_guess);
  EXPECT_EQ(g.status, Status::kInvalidInput);
  expectWellFormed(g);
  EXPECT_TRUE(g.T_target_source.isApprox(Pose::Identity()));
}

TEST_P(Degenerate, SinglePlane) {
  const PointCloud plane = test::plane(0.2);
  const Target target(plane, test::fullTarget());
  const Pose small = fromXyzRpy({0.05, -0.03, 0.02, 0.0, 0.0, deg2rad(0.5)});
  const RegistrationResult r =
      test::run(GetParam(), target, withCovariances(test::movedCopy(plane, small, 0.002, 2)), Pose::Identity());
  EXPECT_EQ(r.status, Status::kDegenerate) << r.reason;
  EXPECT_NE(r.reason.find("degenerate"), std::string::npos);
  EXPECT_LT(r.conditioning, 1e-3);
  expectWellFormed(r);
  // What the plane does pin down (height, roll, pitch) is still right.
  EXPECT_NEAR(r.T_target_source.translation().z(), small.translation().z(), 5e-3);
}

TEST_P(Degenerate, Corridor) {
  const PointCloud corridor = test::corridor(0.2);
  const Target target(corridor, test::fullTarget());
  const Pose small = fromXyzRpy({0.05, -0.03, 0.02, 0.0, 0.0, deg2rad(0.5)});
  const RegistrationResult r =
      test::run(GetParam(), target, withCovariances(test::movedCopy(corridor, small, 0.002, 2)), Pose::Identity());
  EXPECT_EQ(r.status, Status::kDegenerate) << r.reason;
  EXPECT_LT(r.conditioning, SolverParams{}.degeneracy_threshold);
  expectWellFormed(r);
}

TEST_P(Degenerate, NoOverlap) {
  Pose far = Pose::Identity();
  far.translation().z() = 50.0;
  const RegistrationResult r = test::run(GetParam(), roomTarget(), withCovariances(test::room(0.5)), far);
  EXPECT_EQ(r.status, Status::kTooFewCorrespondences) << r.reason;
  EXPECT_EQ(r.inlier_ratio, 0.0);
  expectWellFormed(r);
  EXPECT_TRUE(r.T_target_source.isApprox(far));
}

INSTANTIATE_TEST_SUITE_P(Methods, Degenerate, ::testing::ValuesIn(test::allMethods()),
                         [](const auto& param_info) { return test::name(param_info.param); });

TEST(InvalidInput, MissingTargetStructuresAndBadParameters) {
  const Target bare(test::room(0.25));  // tree only
  const PointCloud src = withCovariances(test::room(0.5));
  const RegistrationResult plane = test::run(Method::kPointToPlane, bare, src, Pose::Identity());
  EXPECT_EQ(plane.status, Status::kInvalidInput);
  EXPECT_NE(plane.reason.find("normals"), std::string::npos) << plane.reason;
  const RegistrationResult gicp = test::run(Method::kGicp, bare, src, Pose::Identity());
  EXPECT_EQ(gicp.status, Status::kInvalidInput);
  EXPECT_NE(gicp.reason.find("covariances"), std::string::npos) << gicp.reason;
  const RegistrationResult ndt = test::run(Method::kNdt, bare, src, Pose::Identity());
  EXPECT_EQ(ndt.status, Status::kInvalidInput);
  EXPECT_NE(ndt.reason.find("NDT grid"), std::string::npos) << ndt.reason;

  IcpParams icp;
  icp.max_correspondence_distance = std::numeric_limits<double>::quiet_NaN();
  EXPECT_EQ(alignIcp(bare, src, Pose::Identity(), icp).status, Status::kInvalidInput);
  NdtParams bad_ratio;
  bad_ratio.outlier_ratio = 1.5;
  const Target with_grid(test::room(0.25), test::fullTarget());
  const RegistrationResult r = alignNdt(with_grid, src, Pose::Identity(), bad_ratio);
  EXPECT_EQ(r.status, Status::kInvalidInput);
  expectWellFormed(r);
  EXPECT_EQ(alignBatchedIcp({}, Pose::Identity()).status, Status::kInvalidInput);
  const SourceTarget null_pair[] = {{&src, nullptr}};
  EXPECT_EQ(alignBatchedIcp(null_pair, Pose::Identity()).status, Status::kInvalidInput);
}

TEST(InvalidInput, NonFiniteSourceCovariancesAreRefusedNotConverged) {
  const Target target(test::room(0.25), test::fullTarget());
  PointCloud src = withCovariances(test::room(0.5));
  src.covariances[5](1, 1) = std::numeric_limits<double>::quiet_NaN();
  const RegistrationResult r = test::run(Method::kGicp, target, src, Pose::Identity());
  EXPECT_EQ(r.status, Status::kInvalidInput);
  EXPECT_NE(r.reason.find("covariances are not finite"), std::string::npos) << r.reason;
  expectWellFormed(r);
}

TEST(InvalidInput, GicpEstimatesMissingSourceCovariances) {
  const Target target(test::room(0.1), test::fullTarget());
  const PointCloud bare_source = test::movedCopy(test::room(0.1), test::knownTransform(), 0.003, 3, 1);
  ASSERT_FALSE(bare_source.hasCovariances());
  const RegistrationResult r = alignGicp(target, bare_source, Pose::Identity());
  EXPECT_EQ(r.status, Status::kConverged) << r.reason;
  EXPECT_LT(test::translationError(r.T_target_source, test::knownTransform()), 2e-3);
}

}  // namespace
}  // namespace rigcal::registration
