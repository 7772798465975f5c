// The voxel pass over a concatenation of voxel-ordered clouds, by merging their orders, is voxelDownsample's
// over the concatenated points bit for bit: the mapper's local map relies on it to be the same map, faster.
#include "rigcal/registration/voxel_ordered_cloud.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <memory>
#include <stdexcept>
#include <vector>

#include "rigcal/registration/voxel_grid.hpp"
#include "scenes.hpp"

namespace rigcal::registration {
namespace {

TEST(VoxelOrderedCloud, MergingTheCloudsIsTheVoxelPassOverTheirConcatenationBitForBit) {
  constexpr double kLeaf = 0.1;
  const PointCloud room = test::room(0.03);
  // Keyframes of a drive: the room placed along a path, far from the origin (the sums are relative to each
  // voxel's first point), overlapping (every voxel of the map in several), with a few points no voxel holds.
  std::vector<std::unique_ptr<VoxelOrderedCloud>> keyframes;
  std::vector<PointCloud> keyframe_points;
  PointCloud concatenation;
  for (int k = 0; k < 6; ++k) {
    Eigen::Isometry3d T = Eigen::Isometry3d::Identity();
    T.rotate(Eigen::AngleAxisd(0.05 * k, Eigen::Vector3d::UnitZ()));
    T.pretranslate(Eigen::Vector3d(4321.7 + 0.31 * k, -987.3 - 0.07 * k, 12.1));
    PointCloud points;
    for (std::size_t i = k; i < room.size(); i += 2) {
      points.points.emplace_back();
      points.points.back() << T * room.points[i].head<3>(), 1.0;
    }
    points.points.insert(points.points.begin() + 17,
                         Eigen::Vector4d(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0, 1.0));
    points.points.emplace_back(1e300, 0.0, 0.0, 1.0);
    concatenation.points.insert(concatenation.points.end(), points.points.begin(), points.points.end());
    keyframes.push_back(std::make_unique<VoxelOrderedCloud>(points, kLeaf));
    EXPECT_EQ(keyframes.back()->byVoxel().size(), points.size() - 2);
    EXPECT_EQ(keyframes.back()->cloudSize(), points.size());
    keyframe_points.push_back(std::move(points));
  }
  std::vector<const VoxelOrderedCloud*> clouds;
  for (const auto& k : keyframes) clouds.push_back(k.get());
  const PointCloud expected = voxelDownsample(concatenation, kLeaf);
  const PointCloud got = voxelDownsampleConcatenation(clouds, kLeaf);
  ASSERT_EQ(got.size(), expected.size());
  for (std::size_t i = 0; i < got.size(); ++i) ASSERT_EQ(got.points[i], expected.points[i]) << "point " << i;

  // Any subset of keyframes (a local map window), and none.
  const std::vector<const VoxelOrderedCloud*> window(clouds.begin() + 2, clouds.end());
  PointCloud window_points;
  for (std::size_t k = 2; k < keyframe_points.size(); ++k)
    window_points.points.insert(window_points.points.end(), keyframe_points[k].points.begin(),
                                keyframe_points[k].points.end());
  const PointCloud window_expected = voxelDownsample(window_points, kLeaf);
  const PointCloud window_got = voxelDownsampleConcatenation(window, kLeaf);
  ASSERT_EQ(window_got.size(), window_expected.size());
  for (std::size_t i = 0; i < window_got.size(); ++i) ASSERT_EQ(window_got.points[i], window_expected.points[i]);
  EXPECT_TRUE(voxelDownsampleConcatenation({}, kLeaf).empty());
}

TEST(VoxelOrderedCloud, RejectsABadOrAnotherLeaf) {
  PointCloud points;
  points.points = {{0.01, 0.02, 0.03, 1.0}, {-0.01, 0.0, 0.0, 1.0}};
  EXPECT_THROW(VoxelOrderedCloud(points, 0.0), std::invalid_argument);
  EXPECT_THROW(VoxelOrderedCloud(points, std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
  const VoxelOrderedCloud at_tenth(points, 0.1);
  ASSERT_EQ(at_tenth.byVoxel().size(), 2u);
  EXPECT_EQ(at_tenth.placeInCloud().front(), 1u);  // voxel -1 before voxel 0 (floor, not truncation)
  EXPECT_EQ(at_tenth.byVoxel().front(), points.points[1].head<3>());
  const VoxelOrderedCloud* clouds[] = {&at_tenth};
  EXPECT_THROW(voxelDownsampleConcatenation(clouds, 0.2), std::invalid_argument);
  EXPECT_THROW(voxelDownsampleConcatenation(clouds, -1.0), std::invalid_argument);
}

}  // namespace
}  // namespace rigcal::registration
