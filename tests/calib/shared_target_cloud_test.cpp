// The later frames' shared target (SharedTargetCloud): one map-frame cloud, each mapping point in it once,
// that scores every frame through its anchor as well as the frame's own near target does, on fewer points
// than the frames' own targets together.
#include <gtest/gtest.h>

#include <vector>

#include "lidar_lidar_sim_dataset.hpp"
#include "rigcal/calib/lidar_lidar/augmented_target.hpp"
#include "rigcal/calib/lidar_lidar/calibration_score.hpp"
#include "rigcal/calib/lidar_lidar/calibration_source.hpp"
#include "rigcal/calib/lidar_lidar/ensemble_plan.hpp"
#include "rigcal/calib/lidar_lidar/shared_target_cloud.hpp"
#include "rigcal/registration/target.hpp"

namespace rigcal::calib {
namespace {

registration::TargetOptions fullTarget() {
  registration::TargetOptions o;
  o.normals_and_covariances = true;
  o.ndt_resolutions = {1.0};
  o.num_threads = 2;
  return o;
}

TEST(SharedTargetCloud, ScoresEveryFrameAsItsOwnNearTargetDoesOnFewerPoints) {
  const auto& data = test::flatParkingLot();
  const auto& d = data.datasets.front();
  const Pose truth = data.truth_T_mapping_calib.at(d.calibration_sensor);
  const std::vector<Pose> poses{d.T_mapping_calib_guess, truth};
  const double radius = nearTargetRadius(data.params);
  const double d_eval = data.params.calibration_eval_max_corr_distance;
  ASSERT_GE(d.frames.size(), 3U);
  SharedTargetCloud shared(d, data.params);
  std::vector<registration::PointCloud> sources;
  std::vector<std::shared_ptr<const registration::Target>> own;
  std::size_t own_points = 0;
  for (std::size_t i = 1; i < d.frames.size(); ++i) {
    sources.push_back(buildSource(*d.frames[i].deskewed, data.params, SourceOptions{}));
    ASSERT_TRUE(shared.add(i, sources.back(), poses, radius, {}));
    AugmentedTargetOptions to;
    to.num_threads = 2;
    to.near_poses = poses;
    to.near_radius = radius;
    own.push_back(buildAugmentedTarget(d, i, sources.back(), data.params, to).target);
    own_points += own.back()->size();
  }
  const registration::Target target(shared.cloud(), fullTarget());
  // The frames look at the same lot from places metres apart: their own targets repeat one another.
  EXPECT_LT(double(target.size()), 0.8 * double(own_points)) << target.size() << " vs " << own_points;
  for (std::size_t k = 0; k < sources.size(); ++k) {
    const std::size_t frame = k + 1;
    const registration::SourceTarget pair{&sources[k], &target, shared.anchor(frame)};
    for (const Pose& T : poses) {
      const CalibrationScore mine = scoreFrame(*own[k], sources[k], T, d_eval, 2);
      const CalibrationScore ours = scoreFrame(pair, T, d_eval, 2);
      // As many correspondences (the shared cloud holds more clouds near the source, never fewer) and as close.
      EXPECT_GE(double(ours.inliers), 0.98 * double(mine.inliers)) << "frame " << frame;
      EXPECT_LT(ours.value, 1.1 * mine.value) << "frame " << frame;
    }
    // Without the anchor the source lands somewhere else on the map.
    const registration::SourceTarget unanchored{&sources[k], &target};
    EXPECT_LT(double(scoreFrame(unanchored, truth, d_eval, 2).inliers),
              0.5 * double(scoreFrame(pair, truth, d_eval, 2).inliers))
        << "frame " << frame;
    // A registration through the anchor answers in the mapping frame: from the guess to the truth.
    const auto res = runRegistrator(Registrator::kGicp, pair, d.T_mapping_calib_guess, data.params, 2, {});
    EXPECT_LT((res.T_target_source.translation() - truth.translation()).norm(), 0.02) << "frame " << frame;
  }
  test::releaseFlatParkingLot();
}

TEST(SharedTargetCloud, AddsEachMappingPointOnceAndStopsAtTheDeadline) {
  const auto& data = test::flatParkingLot();
  const auto& d = data.datasets.front();
  const std::vector<Pose> poses{d.T_mapping_calib_guess};
  const double radius = nearTargetRadius(data.params);
  const registration::PointCloud source = buildSource(*d.frames[1].deskewed, data.params, SourceOptions{});
  SharedTargetCloud shared(d, data.params);
  ASSERT_TRUE(shared.add(1, source, poses, radius, {}));
  const std::size_t points = shared.pointsAdded(), voxels = shared.voxels();
  EXPECT_GT(voxels, 1000U);
  // The same frame again: every point it would add is in already.
  ASSERT_TRUE(shared.add(1, source, poses, radius, {}));
  EXPECT_EQ(shared.pointsAdded(), points);
  EXPECT_EQ(shared.voxels(), voxels);
  // An expired deadline adds nothing and says so.
  SharedTargetCloud late(d, data.params);
  EXPECT_FALSE(late.add(1, source, poses, radius, registration::Deadline::after(std::chrono::milliseconds(0))));
  EXPECT_EQ(late.pointsAdded(), 0U);
  test::releaseFlatParkingLot();
}

}  // namespace
}  // namespace rigcal::calib
