#include "rigcal/registration/nearest_neighbors.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <vector>

#include "rigcal/registration/covariance.hpp"
#include "rigcal/registration/target.hpp"
#include "scenes.hpp"

namespace rigcal::registration {
namespace {

std::vector<Eigen::Vector4d> randomPoints(std::size_t n, double scale, Eigen::Vector3d offset, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-scale, scale);
  std::vector<Eigen::Vector4d> pts(n);
  for (auto& p : pts) p << offset + Eigen::Vector3d(u(rng), u(rng), u(rng) * 0.2), 1.0;
  return pts;
}

// Brute-force sorted squared distances (the reference the tree must reproduce).
std::vector<double> bruteForce(const std::vector<Eigen::Vector4d>& pts, const Eigen::Vector4d& q) {
  std::vector<double> d;
  for (const auto& p : pts) d.push_back((p - q).head<3>().squaredNorm());
  std::sort(d.begin(), d.end());
  return d;
}

class KdTreeTest : public ::testing::TestWithParam<std::size_t> {};

TEST_P(KdTreeTest, MatchesBruteForce) {
  // Far from the origin (UTM-like) on purpose: the tree stores float offsets from the cloud's centre.
  const Eigen::Vector3d offset(4.5e5, 5.4e6, 100.0);
  const auto pts = randomPoints(3000, 20.0, offset, 1);
  KdTreeOptions options;
  options.leaf_size = GetParam();
  const KdTree tree(pts, options);
  ASSERT_EQ(tree.size(), pts.size());
  const auto queries = randomPoints(200, 25.0, offset, 2);
  for (const auto& q : queries) {
    const auto ref = bruteForce(pts, q);
    Neighbor nn;
    ASSERT_TRUE(tree.nearest(q, 1e30, &nn));
    EXPECT_NEAR(nn.sq_distance, ref[0], 1e-3 * (1.0 + ref[0]));
    EXPECT_NEAR((pts[nn.index] - q).head<3>().squaredNorm(), ref[0], 1e-3 * (1.0 + ref[0]));
    Neighbor k[8];
    ASSERT_EQ(tree.knn(q, 8, k), 8u);
    for (int i = 0; i < 8; ++i) EXPECT_NEAR(k[i].sq_distance, ref[i], 1e-3 * (1.0 + ref[i]));
    // Bounded searches: nothing beyond the radius, everything inside it.
    if (ref[4] - ref[3] > 1e-3 * ref[4]) {  // a radius clearly between the 4th and 5th
      EXPECT_EQ(tree.knn(q, 8, k, 0.5 * (ref[3] + ref[4])), 4u);
    }
    const bool found = tree.nearest(q, ref[0] * 0.999, &nn);
    EXPECT_FALSE(found);
    // Hints never change the answer.
    const std::uint32_t hints[2] = {k[3].index, 17};
    Neighbor h[2];
    ASSERT_EQ(tree.knn(q, 2, h, 1e30, hints), 2u);
    EXPECT_NEAR(h[0].sq_distance, ref[0], 1e-3 * (1.0 + ref[0]));
    EXPECT_NEAR(h[1].sq_distance, ref[1], 1e-3 * (1.0 + ref[1]));
    ASSERT_TRUE(tree.nearest(q, 1e30, &nn, 1234));
    EXPECT_NEAR(nn.sq_distance, ref[0], 1e-3 * (1.0 + ref[0]));
  }
}

INSTANTIATE_TEST_SUITE_P(LeafSizes, KdTreeTest, ::testing::Values(1u, 5u, 12u, 64u));

TEST(KdTree, ApproximateNearestIsWithinTheRelativeErrorAndSkipsWork) {
  // A dense surface patch and queries well above it: the case the approximate search is for.
  const auto pts = randomPoints(20000, 5.0, Eigen::Vector3d::Zero(), 4);
  const KdTree tree(pts);
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-4.0, 4.0);
  int not_exact = 0;
  for (int i = 0; i < 300; ++i) {
    const Eigen::Vector4d q(u(rng), u(rng), 1.5 + 0.2 * u(rng), 1.0);
    const double exact = bruteForce(pts, q)[0];
    for (const float eps : {0.25F, 1.0F}) {
      Neighbor nn;
      ASSERT_TRUE(tree.nearest(q, 1e30, &nn, KdTree::kNoHint, eps));
      const double d2 = (pts[nn.index] - q).head<3>().squaredNorm();
      EXPECT_GE(d2, exact * (1.0 - 1e-5));
      EXPECT_LE(d2, exact * (1.0 + eps) * (1.0 + eps) * (1.0 + 1e-5));
      if (d2 > exact * (1.0 + 1e-5)) ++not_exact;
    }
    // The range still holds: nothing beyond it, even approximately.
    Neighbor nn;
    EXPECT_FALSE(tree.nearest(q, exact * 0.999, &nn, KdTree::kNoHint, 1.0F));
    ASSERT_TRUE(tree.nearest(q, 1e30, &nn, KdTree::kNoHint, 0.0F));
    EXPECT_NEAR(nn.sq_distance, exact, 1e-4 * exact);
  }
  EXPECT_GT(not_exact, 0);  // it does take the shortcut somewhere (else the option would do nothing)
}

TEST(KdTree, EmptyTinyAndDuplicates) {
  const KdTree empty;
  Neighbor nn;
  EXPECT_FALSE(empty.nearest(Eigen::Vector4d(0, 0, 0, 1), 1e30, &nn));
  Neighbor k[4];
  EXPECT_EQ(empty.knn(Eigen::Vector4d(0, 0, 0, 1), 4, k), 0u);

  std::vector<Eigen::Vector4d> same(100, Eigen::Vector4d(1, 2, 3, 1));
  const KdTree dup(same);
  EXPECT_EQ(dup.knn(Eigen::Vector4d(1, 2, 3, 1), 4, k), 4u);
  EXPECT_EQ(k[3].sq_distance, 0.0F);

  const std::vector<Eigen::Vector4d> one{Eigen::Vector4d(1, 1, 1, 1)};
  const KdTree single(one);
  EXPECT_EQ(single.knn(Eigen::Vector4d(0, 0, 0, 1), 4, k), 1u);
}

TEST(KdTree, ParallelBuildGivesTheSameTree) {
  const auto pts = randomPoints(5000, 10.0, Eigen::Vector3d::Zero(), 3);
  KdTreeOptions two;
  two.num_threads = 2;
  const KdTree a(pts), b(pts, two);
  EXPECT_EQ(a.leafOrder(), b.leafOrder());
}

TEST(NeighborGraph, RadiusBoundsEveryUnlistedPoint) {
  PointCloud cloud;
  cloud.points = randomPoints(2000, 5.0, Eigen::Vector3d::Zero(), 4);
  const KdTree tree(cloud.points);
  NeighborGraph graph;
  CovarianceOptions options;
  options.num_neighbors = 12;
  estimateCovariances(cloud, tree, options, &graph, 8);
  ASSERT_EQ(graph.degree, 8u);
  for (std::size_t j = 0; j < cloud.size(); j += 37) {
    std::vector<std::uint32_t> listed;
    for (std::size_t r = 0; r < graph.degree; ++r) listed.push_back(graph.neighbor(j, r));
    for (std::size_t k = 0; k < cloud.size(); ++k) {
      if (k == j || std::find(listed.begin(), listed.end(), k) != listed.end()) continue;
      EXPECT_GE((cloud.points[k] - cloud.points[j]).norm(), graph.radius[j] - 1e-5);
    }
  }
}

// Issue #18: a neighbour is stored as a 2-byte offset. One that does not fit is not stored: the point
// lists itself and vouches for nothing (radius 0), so a search from it goes to the tree.
TEST(NeighborGraph, AListWithAnOffsetBeyondTwoBytesIsNotStored) {
  NeighborGraph graph;
  graph.degree = 2;
  graph.offsets.assign(2 * 40000, 0);
  graph.radius.assign(40000, 0.0F);
  const std::uint32_t near[2] = {3, 7}, far[2] = {1, 5 + 32768};
  EXPECT_TRUE(graph.set(5, near, 0.5F));
  EXPECT_EQ(graph.neighbor(5, 0), 3u);
  EXPECT_EQ(graph.neighbor(5, 1), 7u);
  EXPECT_EQ(graph.radius[5], 0.5F);
  EXPECT_FALSE(graph.set(5, far, 0.5F));
  EXPECT_EQ(graph.neighbor(5, 0), 5u);
  EXPECT_EQ(graph.neighbor(5, 1), 5u);
  EXPECT_EQ(graph.radius[5], 0.0F);
  const std::uint32_t edge[2] = {39999 - 32767, 39999};
  EXPECT_TRUE(graph.set(39999, edge, 0.25F)) << "offset -32767 and 0 fit";
  EXPECT_EQ(graph.neighbor(39999, 0), 39999u - 32767u);
}

// In a Target the points are in the tree's leaf order, so almost every point's neighbours fit in two
// bytes: the graph keeps doing its job (a handful of points at the top splits vouch for nothing).
TEST(NeighborGraph, InATargetAlmostEveryPointVouches) {
  PointCloud cloud = test::room(0.03);
  ASSERT_GT(cloud.size(), 2u * 32768u) << "offsets must be able to overflow";
  TargetOptions options;
  options.normals_and_covariances = true;
  const Target target(std::move(cloud), options);
  const NeighborGraph& graph = target.neighborGraph();
  ASSERT_FALSE(graph.empty());
  std::size_t vouching = 0;
  for (const float r : graph.radius) vouching += r > 0.0F ? 1 : 0;
  const double share = double(vouching) / double(graph.radius.size());
  std::printf("%zu points, %.2f %% vouch\n", graph.radius.size(), 100.0 * share);
  EXPECT_GT(share, 0.97);
  // A stored list is the exact nearest points: every other point is at least its radius away.
  const auto& pts = target.cloud().points;
  for (std::size_t j = 0; j < pts.size(); j += 997) {
    if (graph.radius[j] == 0.0F) continue;
    std::vector<std::uint32_t> listed;
    for (std::size_t r = 0; r < graph.degree; ++r) listed.push_back(graph.neighbor(j, r));
    for (std::size_t k = 0; k < pts.size(); ++k) {
      if (k == j || std::find(listed.begin(), listed.end(), k) != listed.end()) continue;
      ASSERT_GE((pts[k] - pts[j]).head<3>().norm(), graph.radius[j] - 1e-4) << j << " " << k;
    }
  }
}

}  // namespace
}  // namespace rigcal::registration
