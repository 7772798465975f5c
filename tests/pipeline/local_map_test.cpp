// LocalMap (pipeline/src): its target and the drive's map are voxelDownsample's pass over the keyframes'
// clouds bit for bit, though made by merging each keyframe's voxel order (what the mapper hashed point by
// point at every keyframe before): the same map, the same registrations.
#include "local_map.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <vector>

#include "../registration/scenes.hpp"
#include "rigcal/registration/voxel_grid.hpp"

namespace rigcal::pipeline {
namespace {

namespace reg = registration;

TEST(LocalMap, ItsTargetAndTheMapAreTheVoxelPassOverTheKeyframesBitForBit) {
  config::Parameters params;
  params.local_map_num_keyframes = 4;
  const double leaf = params.leaf_size_local_map;
  Scan like;
  const Scan scan = reg::toScan(reg::test::room(0.03), like);
  LocalMap map(params, /*use_ndt=*/false, /*deterministic=*/true);
  std::vector<reg::PointCloud> placed;  // each keyframe voxelised in its lidar's frame, placed in the map
  for (int k = 0; k < 7; ++k) {
    Pose T = Pose::Identity();
    T.rotate(Eigen::AngleAxisd(0.07 * k, Eigen::Vector3d::UnitZ()));
    T.pretranslate(Eigen::Vector3d(0.37 * k, -0.11 * k, 0.01 * k));
    map.addKeyframe(scan, T, false);
    placed.push_back(reg::transformed(reg::voxelDownsample(reg::fromScan(scan), leaf), T));
  }
  reg::PointCloud window, all;
  for (std::size_t k = 0; k < placed.size(); ++k) {
    all.points.insert(all.points.end(), placed[k].points.begin(), placed[k].points.end());
    if (k + params.local_map_num_keyframes >= placed.size())
      window.points.insert(window.points.end(), placed[k].points.begin(), placed[k].points.end());
  }
  for (int i = 0; i < 3; ++i) map.beforeRegistration();  // the last keyframe's target is due
  ASSERT_NE(map.target(), nullptr);
  reg::TargetOptions o;
  o.normals_and_covariances = true;
  o.num_threads = std::max(1, params.mapper_num_threads);
  const reg::Target expected(reg::voxelDownsample(window, leaf), o);
  ASSERT_EQ(map.target()->size(), expected.size());
  for (std::size_t i = 0; i < expected.size(); ++i)
    ASSERT_EQ(map.target()->cloud().points[i], expected.cloud().points[i]) << "target point " << i;

  const reg::PointCloud want = reg::voxelDownsample(all, leaf), got = map.allKeyframes();
  ASSERT_EQ(got.size(), want.size());
  for (std::size_t i = 0; i < want.size(); ++i) ASSERT_EQ(got.points[i], want.points[i]) << "map point " << i;
}

}  // namespace
}  // namespace rigcal::pipeline
