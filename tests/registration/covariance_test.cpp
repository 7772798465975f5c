#include "rigcal/registration/covariance.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <random>
#include <algorithm>
#include <vector>

#include <Eigen/Eigenvalues>

#include "rigcal/registration/ndt_grid.hpp"
#include "rigcal/registration/target.hpp"
#include "scenes.hpp"

namespace rigcal::registration {
namespace {

TEST(Covariance, PlaneGivesItsNormalAndPlaneRegularisedCovariance) {
  PointCloud c = test::plane(0.1);
  for (auto& p : c.points) p.z() = 2.0;  // the plane z = 2 seen from the origin below it
  const CovarianceStats stats = estimateCovariances(c);
  EXPECT_EQ(stats.without_neighborhood, 0u);
  ASSERT_TRUE(c.hasNormals() && c.hasCovariances());
  for (std::size_t i = 0; i < c.size(); i += 97) {
    EXPECT_NEAR(c.normals[i].z(), -1.0, 1e-9) << "normal must face the sensor at the origin";
    const Eigen::Matrix3d C = c.covariances[i].topLeftCorner<3, 3>();
    EXPECT_NEAR(C(0, 0), 1.0, 1e-9);
    EXPECT_NEAR(C(1, 1), 1.0, 1e-9);
    EXPECT_NEAR(C(2, 2), 1e-3, 1e-9);
    EXPECT_EQ(c.covariances[i].row(3).norm() + c.covariances[i].col(3).norm(), 0.0);
  }
}

TEST(Covariance, TooFewNeighboursIsIsotropicWithoutNormal) {
  PointCloud c;
  c.add(0, 0, 0);
  c.add(1, 0, 0);
  const CovarianceStats stats = estimateCovariances(c);
  EXPECT_EQ(stats.without_neighborhood, 2u);
  EXPECT_EQ(c.normals[0].norm(), 0.0);
  EXPECT_TRUE((c.covariances[0].topLeftCorner<3, 3>().isIdentity()));
}

TEST(Covariance, SameResultWithTwoThreads) {
  PointCloud a = test::room(0.2), b = a;
  CovarianceOptions two;
  two.num_threads = 2;
  estimateCovariances(a);
  estimateCovariances(b, two);
  for (std::size_t i = 0; i < a.size(); ++i) {
    ASSERT_EQ(a.covariances[i], b.covariances[i]);
    ASSERT_EQ(a.normals[i], b.normals[i]);
  }
}

// The tree-less estimateCovariances (k-NN on a cell grid, the tree only for what the grid cannot prove)
// must give the tree's answer. Jittered so no two neighbours tie at the k-th distance (a tie may pick
// either point); a far-away offset (UTM-like) and a few isolated points that the grid cannot vouch for
// exercise the precision and the tree fallback.
// True when, by exact (double) distances from point i, the neighbour at the boundary of its k-set and the
// next one are equally far within float rounding (whether the set counts the point itself or not).
bool kthNeighbourIsAFloatTie(const PointCloud& c, std::size_t i, int k) {
  std::vector<double> d2;
  d2.reserve(c.size());
  for (const auto& p : c.points) d2.push_back((p.head<3>() - c.points[i].head<3>()).squaredNorm());
  std::sort(d2.begin(), d2.end());
  const auto tie = [&](std::size_t j) { return j + 1 < d2.size() && d2[j + 1] - d2[j] <= 1e-5 * d2[j + 1]; };
  return tie(std::size_t(k) - 1) || tie(std::size_t(k));
}

TEST(Covariance, GridNeighbourhoodsEqualTheTrees) {
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  PointCloud base = test::room(0.12);
  for (auto& p : base.points) p.head<3>() += Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng));
  const std::vector<Eigen::Vector3d> offsets{Eigen::Vector3d::Zero(), Eigen::Vector3d(512345.6, 5412345.7, 230.1)};
  for (const Eigen::Vector3d& offset : offsets) {
    PointCloud a = base;
    for (auto& p : a.points) p.head<3>() += offset;
    for (int i = 0; i < 20; ++i) a.add(offset.x() + 40.0 + 3.0 * i, offset.y() - 7.0 * i, offset.z() + 0.5 * i);
    PointCloud b = a;
    const CovarianceStats grid = estimateCovariances(a);
    const CovarianceStats tree = estimateCovariances(b, KdTree(b.points));
    EXPECT_EQ(grid.without_neighborhood, tree.without_neighborhood);
    std::size_t differ = 0, ties = 0;
    for (std::size_t i = 0; i < a.size(); ++i) {
      // Same neighbour set → the same sums in the same order up to the order of the set: 1e-9 allows that.
      if ((a.covariances[i] - b.covariances[i]).cwiseAbs().maxCoeff() <= 1e-9 &&
          (a.normals[i] - b.normals[i]).cwiseAbs().maxCoeff() <= 1e-9)
        continue;
      // Both compare float distances, each compiler rounding its own way: where the k-th and the next
      // neighbour are equally far to float precision, either is right. Anything else is a wrong answer.
      if (kthNeighbourIsAFloatTie(a, i, CovarianceOptions{}.num_neighbors)) {
        ++ties;
        continue;
      }
      ++differ;
    }
    EXPECT_EQ(differ, 0u) << "of " << a.size() << " points, offset " << offset.transpose();
    EXPECT_LE(ties, 3u) << "float ties are rare on jittered points";
  }
}

// The Target's pass (covariances + neighbour graph, grid first, the given tree for what the grid cannot
// prove or for crowded blocks) against a plain tree query per point: each graph entry is as far as the
// tree's neighbour of the same rank (equal up to the order of ties), the radius is the next other point's
// distance, each covariance is the one of the tree's k nearest. The cloud mixes a jittered room, a
// denser copy (crowded blocks) and isolated points (unproven); 1 and 2 threads give identical results.
// Both rank by float distances (the tree's relative to its centre, up to ~100 m away here: ~1e-5 m).
double floatSlack(double d2) { return 1e-5 * d2 + 1e-4 * std::sqrt(d2); }
bool kthIsATie(const PointCloud& c, std::size_t i, int k) {
  std::vector<double> d2;
  for (const auto& p : c.points) d2.push_back((p.head<3>() - c.points[i].head<3>()).squaredNorm());
  std::sort(d2.begin(), d2.end());
  const auto tie = [&](std::size_t j) { return j + 1 < d2.size() && d2[j + 1] - d2[j] <= floatSlack(d2[j + 1]); };
  return tie(std::size_t(k) - 1) || tie(std::size_t(k));
}

TEST(Covariance, TargetGraphAndCovariancesEqualTheTrees) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> jitter(-0.02, 0.02);
  PointCloud cloud = test::room(0.12);
  for (auto& p : cloud.points) p.head<3>() += Eigen::Vector3d(jitter(rng), jitter(rng), jitter(rng));
  PointCloud dense = test::room(0.02);
  for (auto& p : dense.points) {
    if (p.head<3>().norm() < 1.5)
      cloud.points.push_back(p + Eigen::Vector4d(jitter(rng), jitter(rng), jitter(rng), 0.0) * 0.3);
  }
  for (int i = 0; i < 20; ++i) cloud.add(40.0 + 3.0 * i, -7.0 * i, 0.5 * i);
  const KdTree tree(cloud.points);
  constexpr std::size_t kDegree = 10;
  const int k = CovarianceOptions{}.num_neighbors;
  PointCloud a = cloud, b = cloud;
  NeighborGraph graph_a, graph_b;
  CovarianceOptions two;
  two.num_threads = 2;
  estimateCovariances(a, tree, {}, &graph_a, kDegree);
  estimateCovariances(b, tree, two, &graph_b, kDegree);
  EXPECT_EQ(graph_a.offsets, graph_b.offsets);
  EXPECT_EQ(graph_a.radius, graph_b.radius);
  std::size_t wrong_graph = 0, wrong_shape = 0, ties = 0, unstored = 0, far_neighbour_seen = 0;
  std::vector<Neighbor> nb(kDegree + 2);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    ASSERT_EQ(a.covariances[i], b.covariances[i]) << i;
    const std::size_t found = tree.knn(cloud.points[i], kDegree + 2, nb.data());
    std::vector<double> others;
    for (std::size_t j = 0; j < found; ++j) {
      if (nb[j].index != i) others.push_back((cloud.points[nb[j].index] - cloud.points[i]).head<3>().squaredNorm());
    }
    ASSERT_GE(others.size(), kDegree + 1);
    // This cloud is not in a tree's leaf order (a Target's is): a list with a neighbour more than 32767
    // places away is not stored (2-byte offsets) and the point vouches for nothing.
    bool stored = graph_a.radius[i] > 0.0F;
    for (std::size_t r = 0; r < kDegree && !stored; ++r) stored = graph_a.neighbor(i, r) != i;
    if (!stored) {
      ++unstored;
      const auto far = [&](std::size_t j) { return j > i + 32767 || i > j + 32767; };
      for (std::size_t j = 0; j < kDegree + 2 && j < found; ++j) far_neighbour_seen += far(nb[j].index) ? 1 : 0;
    }
    for (std::size_t r = 0; r < kDegree && stored; ++r) {
      const double d2 = (cloud.points[graph_a.neighbor(i, r)] - cloud.points[i]).head<3>().squaredNorm();
      if (std::abs(d2 - others[r]) > floatSlack(others[r])) {
        ++wrong_graph;
      }
    }
    const double radius = std::sqrt(others[kDegree]);
    if (stored && std::abs(double(graph_a.radius[i]) - radius) > 1e-4) ++wrong_graph;
    // The tree's covariance: the plane-regularised shape of its k nearest (the point among them).
    Eigen::Vector3d mean = Eigen::Vector3d::Zero();
    for (int j = 0; j < k; ++j) mean += cloud.points[nb[j].index].head<3>() - cloud.points[i].head<3>();
    mean /= k;
    Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
    for (int j = 0; j < k; ++j) {
      const Eigen::Vector3d d = cloud.points[nb[j].index].head<3>() - cloud.points[i].head<3>() - mean;
      cov += d * d.transpose() / k;
    }
    Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig;
    eig.computeDirect(cov);
    const Eigen::Vector3d normal = eig.eigenvectors().col(0);
    const Eigen::Matrix3d expected = Eigen::Matrix3d::Identity() - (1.0 - 1e-3) * normal * normal.transpose();
    if ((a.covariances[i].topLeftCorner<3, 3>() - expected).cwiseAbs().maxCoeff() > 1e-6) {
      if (kthIsATie(cloud, i, k)) {
        ++ties;
      } else {
        ++wrong_shape;
      }
    }
  }
  EXPECT_EQ(wrong_graph, 0u) << "of " << cloud.size() << " points";
  EXPECT_LT(unstored, cloud.size() / 4) << "of " << cloud.size() << " points";
  EXPECT_GE(far_neighbour_seen, unstored) << "a list goes unstored only for a neighbour beyond 2-byte offsets";
  EXPECT_EQ(wrong_shape, 0u) << "of " << cloud.size() << " points";
  EXPECT_LE(ties, 20u) << "float ties of the k-th neighbour are rare on jittered points";
}

TEST(NdtGrid, GaussiansOfOccupiedVoxels) {
  const PointCloud c = test::room(0.1);
  NdtGridOptions options;
  options.resolution = 1.0;
  const NdtGrid grid(c, options);
  EXPECT_GT(grid.size(), 100u);
  const NdtCell* cells[27];
  // A floor point: its own voxel holds a flat Gaussian whose thin axis is z.
  const Eigen::Vector4d p(0.45, 0.45, 0.23, 1.0);  // the room's floor is at z = 0.23
  ASSERT_EQ(grid.neighbors(p, NdtNeighborhood::kDirect1, cells), 1u);
  EXPECT_NEAR(cells[0]->mean.z(), 0.23, 1e-9);
  EXPECT_GT(cells[0]->inverse_covariance(2, 2), 50.0 * cells[0]->inverse_covariance(0, 0));
  EXPECT_GE(grid.neighbors(p, NdtNeighborhood::kDirect7, cells), 3u);
  EXPECT_GE(grid.neighbors(p, NdtNeighborhood::kDirect27, cells), grid.neighbors(p, NdtNeighborhood::kDirect7, cells));
  EXPECT_EQ(grid.neighbors(Eigen::Vector4d(100, 100, 100, 1), NdtNeighborhood::kDirect27, cells), 0u);
  EXPECT_THROW((NdtGrid(c, NdtGridOptions{0.0, 6, 0.01})), std::invalid_argument);
}

TEST(Target, BuildsRequestedStructuresAndDropsNonFinitePoints) {
  PointCloud c = test::room(0.2);
  const std::size_t n = c.size();
  c.points.emplace_back(std::nan(""), 0.0, 0.0, 1.0);
  TargetOptions options;
  options.normals_and_covariances = true;
  options.ndt_resolutions = {1.0, 0.5};
  options.num_threads = 2;
  const Target t(std::move(c), options);
  EXPECT_EQ(t.size(), n);
  EXPECT_EQ(t.droppedNonFinite(), 1u);
  EXPECT_TRUE(t.hasNormals() && t.hasCovariances());
  EXPECT_FALSE(t.neighborGraph().empty());
  EXPECT_NE(t.ndtGrid(1.0), nullptr);
  EXPECT_NE(t.ndtGrid(0.5), nullptr);
  EXPECT_EQ(t.ndtGrid(2.0), nullptr);
  // Points are stored in the tree's order: the tree's answers index the stored cloud.
  Neighbor nn;
  ASSERT_TRUE(t.tree().nearest(t.cloud().points[42], 1e-6, &nn));
  EXPECT_EQ(nn.index, 42u);
  // Only the compact float form is kept (issue #18: the 4x4 matrices were most of a target's memory): each
  // point's covariance upper triangle, in the stored order, as estimating them on the stored points gives.
  EXPECT_TRUE(t.cloud().covariances.empty());
  PointCloud again;
  again.points = t.cloud().points;
  NeighborGraph graph;
  estimateCovariances(again, t.tree(), CovarianceOptions{}, &graph, options.neighbor_graph_degree);
  ASSERT_EQ(t.covarianceUpperFloat().size(), 6 * t.size());
  // The Target writes them without the 4x4 matrices: every one bit-identical to the matrices' float.
  for (std::size_t i = 0; i < t.size(); ++i) {
    const Eigen::Matrix4d& C = again.covariances[i];
    const float* u = t.covarianceUpperFloat().data() + 6 * i;
    const float expected[6] = {static_cast<float>(C(0, 0)), static_cast<float>(C(0, 1)), static_cast<float>(C(0, 2)),
                               static_cast<float>(C(1, 1)), static_cast<float>(C(1, 2)), static_cast<float>(C(2, 2))};
    ASSERT_EQ(std::memcmp(u, expected, sizeof expected), 0) << "point " << i;
    ASSERT_EQ(t.normal(i), again.normals[i].head<3>().cast<float>().cast<double>()) << "point " << i;
  }
  EXPECT_EQ(t.neighborGraph().offsets, graph.offsets);
  EXPECT_TRUE(Target(test::room(0.2)).covarianceUpperFloat().empty());
}

}  // namespace
}  // namespace rigcal::registration
