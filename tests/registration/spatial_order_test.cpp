// The sources' visiting order (private, registration/src/spatial_order.hpp): a permutation that keeps
// consecutive points close, deterministic, with non-finite points last.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <numeric>
#include <random>
#include <vector>

#include "spatial_order.hpp"

namespace rigcal::registration::detail {
namespace {

std::vector<Eigen::Vector4d> shuffledGrid(int side, double spacing, unsigned seed) {
  std::vector<Eigen::Vector4d> pts;
  for (int x = 0; x < side; ++x) {
    for (int y = 0; y < side; ++y) {
      for (int z = 0; z < side; ++z) pts.emplace_back(x * spacing, y * spacing, z * spacing, 1.0);
    }
  }
  std::shuffle(pts.begin(), pts.end(), std::mt19937(seed));
  return pts;
}

double pathLength(const std::vector<Eigen::Vector4d>& pts, const std::vector<std::uint32_t>& order) {
  double length = 0.0;
  for (std::size_t i = 1; i < order.size(); ++i) length += (pts[order[i]] - pts[order[i - 1]]).norm();
  return length;
}

TEST(SpatialOrder, IsAPermutationThatWalksThroughSpaceInShortSteps) {
  const auto pts = shuffledGrid(20, 0.25, 3);  // 8000 points, 5 m cube
  const std::vector<std::uint32_t> order = spatialOrder(pts, 0.5);
  std::vector<std::uint32_t> sorted = order;
  std::sort(sorted.begin(), sorted.end());
  std::vector<std::uint32_t> all(pts.size());
  std::iota(all.begin(), all.end(), 0U);
  EXPECT_EQ(sorted, all);
  const double input_steps = pathLength(pts, all) / static_cast<double>(pts.size() - 1);
  const double ordered_steps = pathLength(pts, order) / static_cast<double>(pts.size() - 1);
  // Shuffled: the mean step is about the cube's mean chord (~2.6 m); a Z-order walk over 0.5 m cells
  // of 2x2x2 points steps about one spacing, jumping further only between cells.
  EXPECT_GT(input_steps, 2.0);
  EXPECT_LT(ordered_steps, 0.5);
}

TEST(SpatialOrder, KeepsTheInputOrderWithinACellAndIsDeterministic) {
  const auto pts = shuffledGrid(10, 0.1, 5);  // 1 m cube: all in one 2 m cell
  const std::vector<std::uint32_t> order = spatialOrder(pts, 2.0);
  for (std::size_t i = 0; i < order.size(); ++i) EXPECT_EQ(order[i], i);
  const auto fine = shuffledGrid(10, 0.1, 5);
  EXPECT_EQ(spatialOrder(fine, 0.3), spatialOrder(pts, 0.3));
}

TEST(SpatialOrder, PutsNonFinitePointsLastAndSurvivesHugeExtents) {
  constexpr double kNan = std::numeric_limits<double>::quiet_NaN();
  std::vector<Eigen::Vector4d> pts = {{kNan, 0, 0, 1}, {1e9, 0, 0, 1}, {0, 0, 0, 1},
                                      {0, std::numeric_limits<double>::infinity(), 0, 1}, {0.1, 0, 0, 1}};
  const std::vector<std::uint32_t> order = spatialOrder(pts, 0.05);
  ASSERT_EQ(order.size(), pts.size());
  EXPECT_EQ(std::vector<std::uint32_t>(order.begin(), order.begin() + 3), (std::vector<std::uint32_t>{2, 4, 1}));
  EXPECT_EQ(std::vector<std::uint32_t>(order.begin() + 3, order.end()), (std::vector<std::uint32_t>{0, 3}));
  EXPECT_TRUE(spatialOrder(std::vector<Eigen::Vector4d>{}, 1.0).empty());
}

}  // namespace
}  // namespace rigcal::registration::detail
