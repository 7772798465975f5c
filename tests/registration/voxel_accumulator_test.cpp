// The voxel accumulator fed cloud by cloud gives exactly voxelDownsample over the concatenation: the
// augmented target relies on it to stop between clouds without changing what it builds.
#include "rigcal/registration/voxel_accumulator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "rigcal/registration/voxel_grid.hpp"
#include "scenes.hpp"

namespace rigcal::registration {
namespace {

TEST(VoxelAccumulator, BatchByBatchIsBitIdenticalToOnePass) {
  PointCloud whole = test::room(0.03);
  // Far from the origin, as a map is: the sums relative to each voxel's first point must match too.
  for (auto& p : whole.points) p.head<3>() += Eigen::Vector3d(4321.7, -987.3, 12.1);
  const PointCloud expected = voxelDownsample(whole, 0.05);
  VoxelAccumulator acc(0.05);
  const std::size_t batch = 7919;  // uneven pieces, as mapping clouds are
  for (std::size_t b = 0; b < whole.size(); b += batch) {
    const std::size_t e = std::min(whole.size(), b + batch);
    acc.add(std::span<const Eigen::Vector4d>(whole.points.data() + b, e - b));
  }
  EXPECT_EQ(acc.added(), whole.size());
  const PointCloud got = acc.centroids();
  ASSERT_EQ(got.size(), expected.size());
  ASSERT_EQ(acc.voxels(), expected.size());
  for (std::size_t i = 0; i < got.size(); ++i) ASSERT_EQ(got.points[i], expected.points[i]) << "centroid " << i;
}

TEST(VoxelAccumulator, DropsNonFinitePointsAndRejectsABadLeaf) {
  VoxelAccumulator acc(0.1);
  const std::vector<Eigen::Vector4d> pts = {{0.01, 0.02, 0.03, 1.0},
                                            {std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0, 1.0},
                                            {0.04, 0.05, 0.06, 1.0}};
  acc.add(pts);
  EXPECT_EQ(acc.added(), 3u);
  EXPECT_EQ(acc.dropped(), 1u);
  ASSERT_EQ(acc.centroids().size(), 1u);
  EXPECT_NEAR(acc.centroids().points[0].x(), 0.025, 1e-12);
  EXPECT_THROW(VoxelAccumulator{0.0}, std::invalid_argument);
  EXPECT_THROW(VoxelAccumulator{std::numeric_limits<double>::infinity()}, std::invalid_argument);
}

}  // namespace
}  // namespace rigcal::registration
