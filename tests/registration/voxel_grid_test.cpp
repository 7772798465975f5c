#include "rigcal/registration/voxel_grid.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>

#include "scenes.hpp"

namespace rigcal::registration {
namespace {

TEST(VoxelGrid, OneCentroidPerOccupiedVoxel) {
  PointCloud c;
  c.add(0.1, 0.1, 0.1);
  c.add(0.3, 0.3, 0.3);  // same 1 m voxel as the first
  c.add(1.5, 0.2, 0.2);
  c.add(-0.5, 0.5, 0.5);  // negative side: floor, not truncation
  VoxelGridStats stats;
  const PointCloud out = voxelDownsample(c, 1.0, &stats);
  ASSERT_EQ(out.size(), 3u);
  EXPECT_EQ(stats.input, 4u);
  EXPECT_EQ(stats.output, 3u);
  EXPECT_TRUE(out.points[0].isApprox(Eigen::Vector4d(0.2, 0.2, 0.2, 1.0)));
  EXPECT_TRUE(out.points[1].isApprox(Eigen::Vector4d(1.5, 0.2, 0.2, 1.0)));
  EXPECT_TRUE(out.points[2].isApprox(Eigen::Vector4d(-0.5, 0.5, 0.5, 1.0)));
}

TEST(VoxelGrid, LargeExtentWithSmallLeafDoesNotOverflow) {
  // 200 km across with 1 cm leaves: 2e7 voxels per axis, 8e21 in the box. PCL's VoxelGrid refuses this
  // ("leaf size too small, integer indices would overflow"); 64-bit per-axis keys do not care.
  PointCloud c;
  for (int i = 0; i < 1000; ++i) {
    const double t = i * 200.0;
    c.add(-1e5 + t, 1e5 - t, 0.5 * t);
    c.add(-1e5 + t + 0.001, 1e5 - t, 0.5 * t);  // same voxel as the previous one
  }
  const PointCloud out = voxelDownsample(c, 0.01);
  ASSERT_EQ(out.size(), 1000u);
  for (int i = 0; i < 1000; ++i) {
    const double t = i * 200.0;
    EXPECT_NEAR(out.points[i].x(), -1e5 + t + 0.0005, 1e-6);
    EXPECT_NEAR(out.points[i].y(), 1e5 - t, 1e-6);
  }
}

TEST(VoxelGrid, DropsNonFiniteAndAbsurdPoints) {
  PointCloud c;
  c.add(0.0, 0.0, 0.0);
  c.points.emplace_back(std::numeric_limits<double>::quiet_NaN(), 0.0, 0.0, 1.0);
  c.points.emplace_back(1e300, 0.0, 0.0, 1.0);  // finite, but no int64 voxel can hold it
  VoxelGridStats stats;
  const PointCloud out = voxelDownsample(c, 0.1, &stats);
  EXPECT_EQ(out.size(), 1u);
  EXPECT_EQ(stats.dropped, 2u);
}

TEST(VoxelGrid, RejectsBadLeafSize) {
  const PointCloud c = test::plane(1.0);
  EXPECT_THROW(voxelDownsample(c, 0.0), std::invalid_argument);
  EXPECT_THROW(voxelDownsample(c, -1.0), std::invalid_argument);
  EXPECT_THROW(voxelDownsample(c, std::numeric_limits<double>::quiet_NaN()), std::invalid_argument);
}

TEST(VoxelGrid, DeterministicAndIdempotentOnItsOutput) {
  const PointCloud c = test::room(0.05);
  const PointCloud a = voxelDownsample(c, 0.2);
  const PointCloud b = voxelDownsample(c, 0.2);
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(a.points[i], b.points[i]);
  EXPECT_LT(a.size(), c.size() / 5);
  EXPECT_TRUE(voxelDownsample(PointCloud{}, 0.2).empty());
}

}  // namespace
}  // namespace rigcal::registration
