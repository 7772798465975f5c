// A pair with an anchor (SourceTarget::anchor) registers against a target kept in another frame (a map) and
// must give what the same pair gives with its target in its own frame: the anchor only moves where the
// matching happens, never what is solved for.
#include <gtest/gtest.h>

#include "methods.hpp"
#include "rigcal/registration/evaluator.hpp"
#include "scenes.hpp"

namespace rigcal::registration {
namespace {

// Far from the origin and turned: a map frame in which a rotation step moves the target's points by a lever
// arm of ~150 m, the case where a twist taken in the target's frame would differ most from the pose's.
Pose mapFromFrame() { return fromXyzRpy({120.0, -85.0, 3.0, deg2rad(2.0), deg2rad(-1.0), deg2rad(70.0)}); }

TEST(AnchoredPair, EveryMethodGivesTheResultOfThePairInItsOwnFrame) {
  const Pose truth = test::knownTransform();
  const Pose A = mapFromFrame();
  const PointCloud room = test::room(0.1);
  const Target own(room, test::fullTarget());
  const Target in_map(transformed(room, A), test::fullTarget());
  PointCloud source = test::movedCopy(room, truth, 0.003, 3, 1);
  for (const test::Method m : test::allMethods()) {
    test::RunOptions o;
    o.threads = 2;
    const RegistrationResult local = test::run(m, own, source, Pose::Identity(), o);
    RegistrationResult anchored;
    const SourceTarget pair{&source, &in_map, A};
    switch (m) {
      case test::Method::kPointToPoint:
      case test::Method::kPointToPlane: {
        IcpParams p;
        p.num_threads = 2;
        p.method = m == test::Method::kPointToPoint ? IcpMethod::kPointToPoint : IcpMethod::kPointToPlane;
        anchored = alignIcp(pair, Pose::Identity(), p);
        break;
      }
      case test::Method::kGicp: {
        GicpParams p;
        p.num_threads = 2;
        anchored = alignGicp(pair, Pose::Identity(), p);
        break;
      }
      case test::Method::kNdt: {
        NdtParams p;
        p.num_threads = 2;
        anchored = alignNdt(pair, Pose::Identity(), p);
        break;
      }
    }
    ASSERT_EQ(anchored.status, Status::kConverged) << test::name(m) << ": " << anchored.reason;
    ASSERT_EQ(local.status, Status::kConverged) << test::name(m) << ": " << local.reason;
    // The result is the pose itself, not anchor·pose.
    EXPECT_LT(test::translationError(anchored.T_target_source, truth), 5e-3) << test::name(m);
    EXPECT_LT(test::rotationErrorDeg(anchored.T_target_source, truth), 0.05) << test::name(m);
    if (m == test::Method::kNdt) {
      // NDT's grid is laid along the map's axes, not the frame's: other cells, a result as close to the truth.
      EXPECT_LT(test::translationError(anchored.T_target_source, local.T_target_source), 5e-3);
    } else {
      // The same matches and steps: only the float rounding of normals and tree far from the origin differs,
      // and the results stay a fraction of the solver's last step (1e-4 m, 1e-4 rad) apart.
      EXPECT_LT(test::translationError(anchored.T_target_source, local.T_target_source), 5e-5) << test::name(m);
      EXPECT_LT(test::rotationErrorDeg(anchored.T_target_source, local.T_target_source), 1e-3) << test::name(m);
      EXPECT_NEAR(double(anchored.iterations), double(local.iterations), 1.0) << test::name(m);
      EXPECT_NEAR(anchored.rmse, local.rmse, 1e-6) << test::name(m);
    }
  }
}

TEST(AnchoredPair, BatchedPairsInOneMapFrameShareTheirPose) {
  // Two frames whose targets are both kept in the map frame, each with its own anchor (its pose in the map),
  // and one unknown pose shared by both: the same result as each target built in its own frame.
  const Pose truth = test::knownTransform();
  const Pose elsewhere = fromXyzRpy({2.0, 1.0, 0.0, 0.0, 0.0, deg2rad(40.0)});
  const PointCloud room_a = test::room(0.1);
  const PointCloud room_b = transformed(test::room(0.1), elsewhere);
  const Pose A1 = mapFromFrame();
  const Pose A2 = mapFromFrame() * fromXyzRpy({15.0, 2.0, 0.0, 0.0, 0.0, deg2rad(-25.0)});
  TargetOptions options;
  options.normals_and_covariances = true;
  const Target ta(room_a, options), tb(room_b, options);
  // Both rooms in one map cloud, one Target: what a calibration's shared target is.
  PointCloud both = transformed(room_a, A1);
  for (const auto& p : transformed(room_b, A2).points) both.points.push_back(p);
  const Target map(both, options);
  const PointCloud sa = test::movedCopy(room_a, truth, 0.003, 4, 1), sb = test::movedCopy(room_b, truth, 0.003, 4, 2);
  const SourceTarget own[] = {{&sa, &ta}, {&sb, &tb}};
  const SourceTarget anchored[] = {{&sa, &map, A1}, {&sb, &map, A2}};
  for (const IcpMethod method : {IcpMethod::kPointToPoint, IcpMethod::kPointToPlane}) {
    BatchedIcpParams params;
    params.method = method;
    params.num_threads = 2;
    const RegistrationResult a = alignBatchedIcp(own, Pose::Identity(), params);
    const RegistrationResult b = alignBatchedIcp(anchored, Pose::Identity(), params);
    ASSERT_EQ(b.status, Status::kConverged) << b.reason;
    EXPECT_LT(test::translationError(b.T_target_source, truth), 2e-3);
    EXPECT_LT(test::rotationErrorDeg(b.T_target_source, truth), 0.02);
    EXPECT_LT(test::translationError(b.T_target_source, a.T_target_source), 5e-5);
    EXPECT_LT(test::rotationErrorDeg(b.T_target_source, a.T_target_source), 1e-3);
    EXPECT_EQ(a.inliers, b.inliers);
  }
  // The score the calibrator ranks candidates by: the same under the anchors.
  const Evaluation ea = evaluate(own, truth, 0.1, 2), eb = evaluate(anchored, truth, 0.1, 2);
  EXPECT_EQ(ea.inliers, eb.inliers);
  EXPECT_NEAR(ea.rmse, eb.rmse, 1e-6);
  // Without its anchor the second frame lands in the wrong place of the map: the anchor is what is read.
  const SourceTarget unanchored[] = {{&sa, &map, A1}, {&sb, &map}};
  EXPECT_LT(evaluate(unanchored, truth, 0.1, 2).inliers, ea.inliers * 3 / 4);
}

}  // namespace
}  // namespace rigcal::registration
