// The batched GICP kernel (private, registration/src/gicp_batch.hpp) against the textbook formula:
// W = (base − a·aᵀ)⁻¹, J = [I, −[q]×], H = Σ JᵀWJ, b = Σ JᵀW·r, cost = Σ rᵀW·r.
#include <gtest/gtest.h>

#include <random>
#include <vector>

#include "gicp_batch.hpp"
#include "rigcal/core/pose.hpp"

namespace rigcal::registration::detail {
namespace {

struct Match {
  Eigen::Vector3d q, r, a;
  Eigen::Matrix3d base;
};

std::vector<Match> randomMatches(std::size_t n, bool rank_one, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  std::vector<Match> out;
  for (std::size_t i = 0; i < n; ++i) {
    Match m;
    m.q = 20.0 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    m.r = 0.1 * Eigen::Vector3d(u(rng), u(rng), u(rng));
    const Eigen::Matrix3d A = Eigen::Matrix3d::NullaryExpr([&] { return u(rng); });
    m.base = A * A.transpose() + 0.5 * Eigen::Matrix3d::Identity();  // positive definite
    m.a = rank_one ? Eigen::Vector3d(0.5 * Eigen::Vector3d(u(rng), u(rng), u(rng)).normalized()) : Eigen::Vector3d::Zero();
    out.push_back(m);
  }
  return out;
}

Sym3 upper(const Eigen::Matrix3d& m) { return {m(0, 0), m(0, 1), m(0, 2), m(1, 1), m(1, 2), m(2, 2)}; }

LinearSystem run(const std::vector<Match>& matches, GicpLanes lanes, std::vector<Sym3>* weights) {
  LinearSystem sys;
  GicpBatch batch(lanes);
  weights->assign(matches.size(), Sym3{});
  for (std::size_t i = 0; i < matches.size(); ++i) {
    batch.add(matches[i].q, matches[i].r, upper(matches[i].base), matches[i].a, &(*weights)[i]);
  }
  batch.finish(sys);
  return sys;
}

void expectMatchesFormula(const std::vector<Match>& matches, GicpLanes lanes) {
  LinearSystem expected;
  for (const Match& m : matches) {
    const Eigen::Matrix3d W = (m.base - m.a * m.a.transpose()).inverse();
    Eigen::Matrix<double, 3, 6> J;
    J << Eigen::Matrix3d::Identity(), -skew(m.q);
    expected.H += J.transpose() * W * J;
    expected.b += J.transpose() * W * m.r;
    expected.cost += m.r.dot(W * m.r);
  }
  std::vector<Sym3> weights;
  LinearSystem got = run(matches, lanes, &weights);
  got.H.triangularView<Eigen::StrictlyLower>() = got.H.transpose();
  const double scale = expected.H.cwiseAbs().maxCoeff();
  EXPECT_LT((got.H - expected.H).cwiseAbs().maxCoeff(), 1e-12 * scale);
  EXPECT_LT((got.b - expected.b).cwiseAbs().maxCoeff(), 1e-12 * scale);
  EXPECT_NEAR(got.cost, expected.cost, 1e-12 * std::abs(expected.cost));
  for (std::size_t i = 0; i < matches.size(); ++i) {
    const Eigen::Matrix3d W = (matches[i].base - matches[i].a * matches[i].a.transpose()).inverse();
    const Sym3 e = upper(W);
    for (const auto& [x, y] : {std::pair{weights[i].xx, e.xx}, {weights[i].xy, e.xy}, {weights[i].xz, e.xz},
                               {weights[i].yy, e.yy}, {weights[i].yz, e.yz}, {weights[i].zz, e.zz}}) {
      EXPECT_NEAR(x, y, 1e-12 * W.cwiseAbs().maxCoeff()) << "weight of match " << i;
    }
  }
}

// 77 = two full batches of 32 plus 13, which pads the last lanes: every path of the batch.
TEST(GicpBatch, RankOneSourcesMatchTheFormula) {
  for (GicpLanes lanes : {GicpLanes::kBest, GicpLanes::kBaseline}) expectMatchesFormula(randomMatches(77, true, 1), lanes);
}
TEST(GicpBatch, GeneralSourcesMatchTheFormula) {
  for (GicpLanes lanes : {GicpLanes::kBest, GicpLanes::kBaseline}) expectMatchesFormula(randomMatches(77, false, 2), lanes);
}
TEST(GicpBatch, FewerMatchesThanOneLaneGroup) {
  for (GicpLanes lanes : {GicpLanes::kBest, GicpLanes::kBaseline}) expectMatchesFormula(randomMatches(3, true, 3), lanes);
}

// A registration must not depend on the CPU it runs on: the AVX2 and the baseline builds give the same
// bits (same operations in the same order, no fused multiply-add).
TEST(GicpBatch, Avx2AndBaselineGiveIdenticalBits) {
  if (!GicpBatch::avx2Available()) GTEST_SKIP() << "this CPU has no AVX2: only the baseline runs here";
  const std::vector<Match> m = randomMatches(77, true, 5);
  std::vector<Sym3> wa, wb;
  const LinearSystem a = run(m, GicpLanes::kBest, &wa), b = run(m, GicpLanes::kBaseline, &wb);
  EXPECT_EQ(a.H, b.H);
  EXPECT_EQ(a.b, b.b);
  EXPECT_EQ(a.cost, b.cost);
  for (std::size_t i = 0; i < m.size(); ++i) {
    EXPECT_EQ(wa[i].xx, wb[i].xx);
    EXPECT_EQ(wa[i].xy, wb[i].xy);
    EXPECT_EQ(wa[i].zz, wb[i].zz);
  }
}

TEST(GicpBatch, FinishStartsAFreshSum) {
  const std::vector<Match> m = randomMatches(40, true, 4);
  GicpBatch batch;
  std::vector<Sym3> w(m.size());
  LinearSystem first, second;
  for (std::size_t i = 0; i < m.size(); ++i) batch.add(m[i].q, m[i].r, upper(m[i].base), m[i].a, &w[i]);
  batch.finish(first);
  for (std::size_t i = 0; i < m.size(); ++i) batch.add(m[i].q, m[i].r, upper(m[i].base), m[i].a, &w[i]);
  batch.finish(second);
  EXPECT_EQ(first.H, second.H);
  EXPECT_EQ(first.b, second.b);
  EXPECT_EQ(first.cost, second.cost);
  LinearSystem empty;
  batch.finish(empty);
  EXPECT_EQ(empty.H, Matrix6d::Zero());
  EXPECT_EQ(empty.cost, 0.0);
}

}  // namespace
}  // namespace rigcal::registration::detail
