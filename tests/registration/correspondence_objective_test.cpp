// The matcher's subsample for coarse-to-fine (private, registration/src/correspondence_objective.hpp):
// every stride-th point of each source, however the sources split into chunks.
#include <gtest/gtest.h>

#include <array>

#include "correspondence_objective.hpp"
#include "scenes.hpp"

namespace rigcal::registration::detail {
namespace {

std::size_t inliersAtIdentity(CorrespondenceObjective& objective) {
  const std::optional<LinearSystem> sys = objective.linearize(Pose::Identity(), Deadline{});
  return sys ? sys->inliers : 0;
}

TEST(CorrespondenceObjective, UseEveryMatchesEveryStrideThPointOfEachSource) {
  const PointCloud cloud = test::room(0.1);
  const Target target(cloud, TargetOptions{});
  // Each source point lies on a target point, so all of them match. The second source is short and of
  // odd length: its points start mid-chunk in the concatenation.
  PointCloud second;
  second.points.assign(cloud.points.begin(), cloud.points.begin() + 1001);
  const std::array<SourceTarget, 2> pairs{SourceTarget{&cloud, &target}, SourceTarget{&second, &target}};
  CorrespondenceObjective objective(pairs, Residual::kPointToPoint, 0.5, 2);
  const std::size_t all = cloud.size() + second.size();
  ASSERT_GT(cloud.size(), 4000U);
  EXPECT_EQ(inliersAtIdentity(objective), all);
  for (const std::size_t stride : {2U, 4U, 8U}) {
    ASSERT_TRUE(objective.useEvery(stride));
    EXPECT_EQ(inliersAtIdentity(objective), (cloud.size() + stride - 1) / stride + (second.size() + stride - 1) / stride)
        << stride;
  }
  // Not a power of two, or past the chunk size: refused, the last stride stays.
  EXPECT_FALSE(objective.useEvery(0));
  EXPECT_FALSE(objective.useEvery(3));
  EXPECT_FALSE(objective.useEvery(4096));
  EXPECT_EQ(inliersAtIdentity(objective), (cloud.size() + 7) / 8 + (second.size() + 7) / 8);
  ASSERT_TRUE(objective.useEvery(1));
  EXPECT_EQ(inliersAtIdentity(objective), all);
}

}  // namespace
}  // namespace rigcal::registration::detail
