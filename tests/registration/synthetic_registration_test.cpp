// Registration on synthetic scenes: runs everywhere (no shared data needed), fast enough for the
// sanitizer builds.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <string>
#include <thread>

#include "sanitizers.hpp"
#include "methods.hpp"
#include "rigcal/registration/covariance.hpp"
#include "scenes.hpp"

namespace rigcal::registration {
namespace {

using test::Method;

struct RoomPair {
  Target target;
  PointCloud source;
  Pose truth = test::knownTransform();
  RoomPair() : target(test::room(0.1), test::fullTarget()) {
    source = test::movedCopy(test::room(0.1), truth, 0.003, 3, 1);
    estimateCovariances(source);
  }
};

const RoomPair& roomPair() {
  static const RoomPair pair;
  return pair;
}

class SyntheticRoom : public ::testing::TestWithParam<Method> {};

TEST_P(SyntheticRoom, RecoversKnownTransform) {
  const RoomPair& p = roomPair();
  const RegistrationResult r = test::run(GetParam(), p.target, p.source, Pose::Identity());
  EXPECT_EQ(r.status, Status::kConverged) << r.reason;
  EXPECT_TRUE(r.converged);
  EXPECT_LT(test::translationError(r.T_target_source, p.truth), 2e-3);
  EXPECT_LT(test::rotationErrorDeg(r.T_target_source, p.truth), 0.02);
  EXPECT_GT(r.inlier_ratio, 0.95);
  EXPECT_LT(r.rmse, 0.05);
  EXPECT_GT(r.conditioning, 0.01);
  EXPECT_GT(r.iterations, 1);
}

TEST_P(SyntheticRoom, SameResultWithOneAndTwoThreads) {
  const RoomPair& p = roomPair();
  test::RunOptions two;
  two.threads = 2;
  const RegistrationResult a = test::run(GetParam(), p.target, p.source, Pose::Identity());
  const RegistrationResult b = test::run(GetParam(), p.target, p.source, Pose::Identity(), two);
  EXPECT_EQ(a.T_target_source.matrix(), b.T_target_source.matrix());  // bit-identical
  EXPECT_EQ(a.iterations, b.iterations);
  EXPECT_EQ(a.rmse, b.rmse);
  EXPECT_EQ(a.fitness, b.fitness);
  EXPECT_EQ(a.inliers, b.inliers);
}

TEST_P(SyntheticRoom, StopsAtMaxIterations) {
  const RoomPair& p = roomPair();
  test::RunOptions o;
  o.max_iterations = 2;
  const RegistrationResult r = test::run(GetParam(), p.target, p.source, Pose::Identity(), o);
  EXPECT_EQ(r.status, Status::kMaxIterations) << r.reason;
  EXPECT_EQ(r.iterations, 2);
  EXPECT_FALSE(r.converged);
  // Still better than where it started.
  EXPECT_LT(test::translationError(r.T_target_source, p.truth), test::translationError(Pose::Identity(), p.truth));
}

INSTANTIATE_TEST_SUITE_P(Methods, SyntheticRoom, ::testing::ValuesIn(test::allMethods()),
                         [](const auto& param_info) { return test::name(param_info.param); });

TEST(SharedTarget, ConcurrentRegistrationsMatchSequentialOnes) {
  const RoomPair& p = roomPair();
  const RegistrationResult gicp = test::run(Method::kGicp, p.target, p.source, Pose::Identity());
  const RegistrationResult ndt = test::run(Method::kNdt, p.target, p.source, Pose::Identity());
  RegistrationResult gicp2, ndt2;
  test::RunOptions two;
  two.threads = 2;
  std::thread a([&] { gicp2 = test::run(Method::kGicp, p.target, p.source, Pose::Identity(), two); });
  std::thread b([&] { ndt2 = test::run(Method::kNdt, p.target, p.source, Pose::Identity()); });
  a.join();
  b.join();
  EXPECT_EQ(gicp.T_target_source.matrix(), gicp2.T_target_source.matrix());
  EXPECT_EQ(ndt.T_target_source.matrix(), ndt2.T_target_source.matrix());
}

TEST(Deadline, ReturnsInTimeWithTheBestSoFar) {
  // 300k source points: an NDT iteration takes far longer than the budget on any machine.
  const PointCloud big = test::movedCopy(test::room(0.03), test::knownTransform(), 0.003);
  const Target target(test::room(0.1), test::fullTarget());
  for (const Method m : {Method::kNdt, Method::kPointToPoint}) {
    const auto budget = std::chrono::milliseconds(30);
    const auto start = std::chrono::steady_clock::now();
    const RegistrationResult r = test::run(m, target, big, Pose::Identity(), {}, Deadline::after(budget));
    const auto elapsed = std::chrono::steady_clock::now() - start;
    EXPECT_EQ(r.status, Status::kTimeout) << r.reason;
    // It overruns by at most one chunk of 512 points per thread (a few ms even under sanitizers); the
    // slack is for a loaded 2-core CI machine that deschedules us. Unbounded, this takes seconds.
    if (rigcal::test::kWallClockAsserted) {
      EXPECT_LT(elapsed, budget + std::chrono::milliseconds(400)) << test::name(m);
    }
    EXPECT_TRUE(r.T_target_source.matrix().allFinite());
    EXPECT_LE(test::translationError(r.T_target_source, test::knownTransform()),
              test::translationError(Pose::Identity(), test::knownTransform()) + 1e-12);
    EXPECT_FALSE(std::isnan(r.rmse) || std::isnan(r.fitness));
  }
}

TEST(Deadline, ExpiredBeforeStartReturnsTheGuess) {
  const RoomPair& p = roomPair();
  Pose guess = Pose::Identity();
  guess.translation().x() = 0.1;
  const RegistrationResult r =
      test::run(Method::kGicp, p.target, p.source, guess, {}, Deadline::after(std::chrono::seconds(-1)));
  EXPECT_EQ(r.status, Status::kTimeout);
  EXPECT_EQ(r.iterations, 0);
  EXPECT_TRUE(r.T_target_source.isApprox(guess));
}

TEST(Deadline, CancelTokenStopsARegistration) {
  const PointCloud big = test::movedCopy(test::room(0.03), test::knownTransform(), 0.003);
  const Target target(test::room(0.1), test::fullTarget());
  CancelToken token;
  std::thread canceller([&] {
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
    token.cancel();
  });
  const RegistrationResult r = test::run(Method::kNdt, target, big, Pose::Identity(), {}, Deadline::never(&token));
  canceller.join();
  EXPECT_EQ(r.status, Status::kCancelled) << r.reason;
  EXPECT_TRUE(r.T_target_source.matrix().allFinite());
}

TEST(NdtParameters, StepSizeCapsEachUpdate) {
  // Upstream's step_size bounds every update's (metres, radians) norm: three capped steps from the
  // identity cannot get further than three step sizes, while the default step reaches the truth.
  const RoomPair& p = roomPair();
  NdtParams capped;
  capped.step_size = 0.02;
  capped.max_iterations = 3;
  const RegistrationResult r = alignNdt(p.target, p.source, Pose::Identity(), capped);
  EXPECT_EQ(r.status, Status::kMaxIterations) << r.reason;
  EXPECT_GT(r.T_target_source.translation().norm(), 0.01);  // it did move
  EXPECT_LE(r.T_target_source.translation().norm(), 3 * 0.02 * 1.01);
  EXPECT_LE(rotationAngle(r.T_target_source), 3 * 0.02 * 1.01);
  const RegistrationResult full = alignNdt(p.target, p.source, Pose::Identity(), NdtParams{});
  EXPECT_EQ(full.status, Status::kConverged) << full.reason;
  EXPECT_LT(test::translationError(full.T_target_source, p.truth), 2e-3);
}

TEST(NdtParameters, EachResolutionUsesItsOwnGridOfOneSharedTarget) {
  const RoomPair& p = roomPair();
  TargetOptions options;
  options.ndt_resolutions = {0.5, 1.0, 2.0};
  const Target target(test::room(0.1), options);
  ASSERT_NE(target.ndtGrid(0.5), nullptr);
  EXPECT_GT(target.ndtGrid(0.5)->size(), target.ndtGrid(2.0)->size());
  for (const double resolution : options.ndt_resolutions) {
    NdtParams params;
    params.resolution = resolution;
    const RegistrationResult r = alignNdt(target, p.source, Pose::Identity(), params);
    EXPECT_EQ(r.status, Status::kConverged) << resolution << ": " << r.reason;
    // Coarser cells blur the room's corners: the bias grows with the cell (8 mm at 2 m here).
    EXPECT_LT(test::translationError(r.T_target_source, p.truth), 5e-3 * resolution) << resolution;
  }
  NdtParams missing;
  missing.resolution = 0.75;
  const RegistrationResult r = alignNdt(target, p.source, Pose::Identity(), missing);
  EXPECT_EQ(r.status, Status::kInvalidInput);
  EXPECT_NE(r.reason.find("0.75"), std::string::npos) << r.reason;
}

TEST(BatchedIcp, OneTransformForSeveralPairs) {
  // Two "frames": the room and a second room seen from elsewhere, each its own target, one unknown
  // T_target_source shared by both.
  const Pose truth = test::knownTransform();
  const Pose elsewhere = fromXyzRpy({2.0, 1.0, 0.0, 0.0, 0.0, deg2rad(40.0)});
  const PointCloud room_a = test::room(0.1);
  const PointCloud room_b = transformed(test::room(0.1), elsewhere);
  TargetOptions options;
  options.normals_and_covariances = true;
  const Target ta(room_a, options), tb(room_b, options);
  const PointCloud sa = test::movedCopy(room_a, truth, 0.003, 4, 1), sb = test::movedCopy(room_b, truth, 0.003, 4, 2);
  const SourceTarget pairs[] = {{&sa, &ta}, {&sb, &tb}};
  for (const IcpMethod method : {IcpMethod::kPointToPoint, IcpMethod::kPointToPlane}) {
    BatchedIcpParams params;
    params.method = method;
    params.num_threads = 2;
    const RegistrationResult r = alignBatchedIcp(pairs, Pose::Identity(), params);
    EXPECT_EQ(r.status, Status::kConverged) << r.reason;
    EXPECT_LT(test::translationError(r.T_target_source, truth), 2e-3);
    EXPECT_LT(test::rotationErrorDeg(r.T_target_source, truth), 0.02);
    EXPECT_GT(r.inlier_ratio, 0.95);
    EXPECT_EQ(r.inliers, static_cast<std::size_t>(r.inlier_ratio * (sa.size() + sb.size()) + 0.5));
  }
}

}  // namespace
}  // namespace rigcal::registration
