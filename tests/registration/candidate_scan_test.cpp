// The candidate scan of the grid all-k-NN (private, registration/src/candidate_scan.hpp): every path
// (scalar, SSE2, AVX2) must give the first k candidates below the bound, stably sorted by their float
// distance, bit for bit, whatever the number of candidates (padding lanes included) and however many tie.
#include <gtest/gtest.h>

#include <algorithm>
#include <limits>
#include <random>
#include <vector>

#include "candidate_scan.hpp"

namespace rigcal::registration::detail {
namespace {

struct Candidates {
  std::vector<float> x, y, z;
  std::vector<std::uint32_t> ids;
  std::size_t real = 0;  // before the padding

  [[nodiscard]] CandidateBlock block() const { return {x.data(), y.data(), z.data(), ids.data(), x.size()}; }
};

// `m` candidates in [-1, 1]³; on a coarse lattice when `ties`, so that many are equally far from a query.
Candidates randomCandidates(std::size_t m, bool ties, std::mt19937& rng) {
  std::uniform_real_distribution<float> u(-1.0F, 1.0F);
  std::uniform_int_distribution<int> lattice(-3, 3);
  Candidates c;
  c.real = m;
  const std::size_t padded = (m + kCandidateLanes - 1) / kCandidateLanes * kCandidateLanes;
  for (std::size_t j = 0; j < padded; ++j) {
    const bool pad = j >= m;
    const auto coord = [&] {
      if (pad) return std::numeric_limits<float>::infinity();
      return ties ? 0.25F * static_cast<float>(lattice(rng)) : u(rng);
    };
    c.x.push_back(coord());
    c.y.push_back(coord());
    c.z.push_back(coord());
    c.ids.push_back(pad ? 0xFFFFFFFFU : static_cast<std::uint32_t>(1000 + j));
  }
  return c;
}

struct Answer {
  std::vector<Neighbor> best;
  std::size_t count = 0;
  float worst = 0.0F;
};

Answer scanWith(CandidateScanPath path, const Candidates& c, const float q[3], std::size_t k, float bound) {
  Answer a;
  a.best.assign(k, Neighbor{7, -1.0F});
  TopK top{a.best.data(), k, 0, bound};
  candidateScan(path)(c.block(), q[0], q[1], q[2], top);
  a.count = top.count;
  a.worst = top.worst;
  a.best.resize(a.count);
  return a;
}

// The textbook answer: candidates below the bound, stably sorted by distance, the first k.
std::vector<Neighbor> firstKBelow(const Candidates& c, const float q[3], std::size_t k, float bound) {
  std::vector<Neighbor> all;
  for (std::size_t j = 0; j < c.real; ++j) {
    const float ex = c.x[j] - q[0], ey = c.y[j] - q[1], ez = c.z[j] - q[2];
    const float d = ex * ex + ey * ey + ez * ez;
    if (d < bound) all.push_back({c.ids[j], d});
  }
  std::stable_sort(all.begin(), all.end(), [](const Neighbor& a, const Neighbor& b) { return a.sq_distance < b.sq_distance; });
  all.resize(std::min(all.size(), k));
  return all;
}

void expectSame(const std::vector<Neighbor>& a, const std::vector<Neighbor>& b, const char* what) {
  ASSERT_EQ(a.size(), b.size()) << what;
  for (std::size_t i = 0; i < a.size(); ++i) {
    EXPECT_EQ(a[i].index, b[i].index) << what << " rank " << i;
    EXPECT_EQ(a[i].sq_distance, b[i].sq_distance) << what << " rank " << i;
  }
}

TEST(CandidateScan, EveryPathGivesTheFirstKBelowTheBound) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> u(-1.0F, 1.0F);
  std::uniform_real_distribution<float> bound_of(0.05F, 3.0F);
  std::size_t cases = 0, short_of_k = 0, tied_kth = 0;
  for (std::size_t m = 0; m <= 41; ++m) {  // every remainder modulo the SSE2 and AVX2 widths, and none
    for (const std::size_t k : {1, 3, 8, 9, 10, 16, 17}) {  // AVX2 keeps k ≤ 16 in registers
      for (const bool ties : {false, true}) {
        for (int trial = 0; trial < 6; ++trial) {
          const Candidates c = randomCandidates(m, ties, rng);
          const float q[3] = {ties ? 0.0F : u(rng), ties ? 0.25F : u(rng), ties ? 0.0F : u(rng)};
          const float bound = trial % 2 == 0 ? std::numeric_limits<float>::infinity() : bound_of(rng);
          const std::vector<Neighbor> expected = firstKBelow(c, q, k, bound);
          for (const auto path : {CandidateScanPath::kScalar, CandidateScanPath::kSse2, CandidateScanPath::kAvx2}) {
            const Answer a = scanWith(path, c, q, k, bound);
            expectSame(a.best, expected, path == CandidateScanPath::kScalar ? "scalar"
                                         : path == CandidateScanPath::kSse2 ? "sse2"
                                                                            : "avx2");
            EXPECT_EQ(a.worst, a.count == k ? expected.back().sq_distance : bound);
          }
          ++cases;
          if (expected.size() < k) ++short_of_k;
          if (expected.size() == k && m > k) {
            // Some candidate after the k-th as far as it: the first offered must have won.
            std::size_t equal = 0;
            for (std::size_t j = 0; j < m; ++j) {
              const float ex = c.x[j] - q[0], ey = c.y[j] - q[1], ez = c.z[j] - q[2];
              if (ex * ex + ey * ey + ez * ez == expected.back().sq_distance) ++equal;
            }
            std::size_t listed = 0;
            for (const Neighbor& n : expected) listed += n.sq_distance == expected.back().sq_distance;
            if (equal > listed) ++tied_kth;
          }
        }
      }
    }
  }
  // The cases cover what they are meant to: fewer candidates than k below the bound, and k-th ties.
  EXPECT_GT(short_of_k, cases / 10);
  EXPECT_GT(tied_kth, cases / 20);
}

TEST(CandidateScan, FastestPathIsAvailableAndScalarIsTheFallback) {
  const CandidateScanPath fastest = fastestCandidateScanPath();
  EXPECT_NE(candidateScan(fastest), nullptr);
  EXPECT_NE(candidateScan(CandidateScanPath::kScalar), nullptr);
#if defined(__x86_64__)
  EXPECT_NE(fastest, CandidateScanPath::kScalar);  // SSE2 is x86-64's baseline
  EXPECT_NE(candidateScan(CandidateScanPath::kSse2), candidateScan(CandidateScanPath::kScalar));
#endif
}

}  // namespace
}  // namespace rigcal::registration::detail
