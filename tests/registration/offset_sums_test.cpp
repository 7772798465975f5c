// The covariance sums kernel (private, registration/src/offset_sums.hpp): the fastest path gives the
// plain loop's sums bit for bit, and the plain loop gives Σd and Σd·dᵀ.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "offset_sums.hpp"

namespace rigcal::registration::detail {
namespace {

TEST(OffsetSums, FastestPathEqualsThePlainLoopBitForBit) {
  std::mt19937 rng(5);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Eigen::Vector4d> points;
  const Eigen::Vector3d far(512345.6, 5412345.7, 230.1);  // offsets of nearby points far from the origin
  for (int i = 0; i < 200; ++i) {
    const Eigen::Vector3d p = far + 0.3 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    points.emplace_back(p.x(), p.y(), p.z(), i % 3 == 0 ? 1.0 : u(rng));  // w must not matter
  }
  std::uniform_int_distribution<std::uint32_t> pick(0, static_cast<std::uint32_t>(points.size() - 1));
  const OffsetSumsKernel fastest = fastestOffsetSums();
  for (std::size_t found = 0; found <= 25; ++found) {
    for (int trial = 0; trial < 20; ++trial) {
      std::vector<Neighbor> nb(found);
      for (auto& n : nb) n = {pick(rng), 0.0F};
      const Eigen::Vector4d& origin = points[pick(rng)];
      OffsetSums plain{}, fast{};
      offsetSumsScalar(points.data(), nb.data(), found, origin, &plain);
      fastest(points.data(), nb.data(), found, origin, &fast);
      for (int l = 0; l < 3; ++l) {
        EXPECT_EQ(fast.s[l], plain.s[l]) << found;
        EXPECT_EQ(fast.x[l], plain.x[l]) << found;
        EXPECT_EQ(fast.yz[l], plain.yz[l]) << found;
      }
      // The plain loop against Eigen's sums of the same offsets.
      Eigen::Vector3d sum = Eigen::Vector3d::Zero();
      Eigen::Matrix3d outer = Eigen::Matrix3d::Zero();
      for (const Neighbor& n : nb) {
        const Eigen::Vector3d d = (points[n.index] - origin).head<3>();
        sum += d;
        outer += d * d.transpose();
      }
      const double tol = 1e-12;
      EXPECT_NEAR(plain.s[0], sum.x(), tol);
      EXPECT_NEAR(plain.s[2], sum.z(), tol);
      EXPECT_NEAR(plain.x[1], outer(0, 1), tol);
      EXPECT_NEAR(plain.x[2], outer(0, 2), tol);
      EXPECT_NEAR(plain.yz[0], outer(1, 1), tol);
      EXPECT_NEAR(plain.yz[1], outer(1, 2), tol);
      EXPECT_NEAR(plain.yz[2], outer(2, 2), tol);
    }
  }
}

}  // namespace
}  // namespace rigcal::registration::detail
