// The near crop of a later frame's augmented target (SourceNeighbourhood): every mapping point within its
// radius of the placed source is kept, so the scores and the coarse registrations see what the box crop
// gave them, on fewer points.
#include <gtest/gtest.h>

#include <cmath>

#include "lidar_lidar_sim_dataset.hpp"
#include "rigcal/calib/lidar_lidar/augmented_target.hpp"
#include "rigcal/calib/lidar_lidar/calibration_score.hpp"
#include "rigcal/calib/lidar_lidar/calibration_source.hpp"
#include "rigcal/calib/lidar_lidar/source_neighbourhood.hpp"
#include "rigcal/registration/target.hpp"

namespace rigcal::calib {
namespace {

TEST(SourceNeighbourhood, HoldsEveryPointWithinTheRadiusAndNothingFarBeyond) {
  registration::PointCloud source;
  source.points = {{0.0, 0.0, 0.0, 1.0}, {10.3, -4.7, 1.2, 1.0}};
  const Pose shift(Eigen::Translation3d(100.0, 0.0, 0.0));
  const double radius = 0.6;
  const SourceNeighbourhood near(source, {Pose::Identity(), shift}, radius);
  for (const Pose& T : {Pose::Identity(), shift}) {
    for (const auto& p : source.points) {
      const Eigen::Vector3d c = T * p.head<3>();
      // Points on a sphere just inside the radius around each placed source point are all held.
      for (int i = 0; i < 200; ++i) {
        const double z = -1.0 + 2.0 * (i + 0.5) / 200.0, a = 2.399963 * i;
        const Eigen::Vector3d dir(std::sqrt(1 - z * z) * std::cos(a), std::sqrt(1 - z * z) * std::sin(a), z);
        EXPECT_TRUE(near.contains(c + 0.999 * radius * dir)) << "around " << c.transpose();
        EXPECT_FALSE(near.contains(c + 2.0 * std::sqrt(3.0) * radius * 1.001 * dir)) << "around " << c.transpose();
      }
    }
  }
  EXPECT_FALSE(near.contains({50.0, 0.0, 0.0}));
  EXPECT_FALSE(near.contains({NAN, 0.0, 0.0}));
  EXPECT_THROW(SourceNeighbourhood(source, {Pose::Identity()}, 0.0), std::invalid_argument);
}

// On the parking lot: the near target (source under the guess and the truth) scores the truth and the
// guess exactly as the box target does, and is much smaller.
TEST(AugmentedTarget, NearCropKeepsTheScoresOfItsPosesOnFewerPoints) {
  const auto& data = test::flatParkingLot();
  const auto& d = data.datasets.front();
  const Pose truth = data.truth_T_mapping_calib.at(d.calibration_sensor);
  const std::size_t frame = d.frames.size() - 1;
  const registration::PointCloud source = buildSource(*d.frames[frame].deskewed, data.params, SourceOptions{});
  AugmentedTargetOptions to;
  to.num_threads = 2;
  const auto box = buildAugmentedTarget(d, frame, source, data.params, to);
  to.near_poses = {d.T_mapping_calib_guess, truth};
  to.near_radius = nearTargetRadius(data.params);
  const auto near = buildAugmentedTarget(d, frame, source, data.params, to);
  EXPECT_LT(double(near.target->size()), 0.85 * double(box.target->size()));
  const double d_eval = data.params.calibration_eval_max_corr_distance;
  for (const Pose& T : {truth, d.T_mapping_calib_guess}) {
    const auto a = scoreFrame(*box.target, source, T, d_eval, 2);
    const auto b = scoreFrame(*near.target, source, T, d_eval, 2);
    EXPECT_EQ(a.inliers, b.inliers);
    EXPECT_NEAR(a.value, b.value, 1e-9 * a.value);
  }
  // What a coarse registration at max_corr_dist_coarse from the truth sees: the same correspondences.
  const double coarse = data.params.max_corr_dist_coarse;
  EXPECT_EQ(scoreFrame(*box.target, source, truth, coarse, 2).inliers,
            scoreFrame(*near.target, source, truth, coarse, 2).inliers);
  test::releaseFlatParkingLot();
}

}  // namespace
}  // namespace rigcal::calib
