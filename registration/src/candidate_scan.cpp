#include "candidate_scan.hpp"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include <algorithm>
#include <limits>

#include "cpu_features.hpp"

namespace rigcal::registration::detail {

namespace {

void scanScalar(const CandidateBlock& b, float qx, float qy, float qz, TopK& top) {
  for (std::size_t j = 0; j < b.size; ++j) {
    const float ex = b.x[j] - qx, ey = b.y[j] - qy, ez = b.z[j] - qz;
    const float d = ex * ex + ey * ey + ez * ez;
    if (d < top.worst) top.offer(b.ids[j], d);
  }
}

#if defined(__x86_64__)
// Lane l of `mask` set: candidate l beat the bound as it was before the group; offer() checks again
// against the bound as the group's earlier lanes tighten it.
[[gnu::always_inline]] inline void offerLanes(unsigned mask, const float* d, const std::uint32_t* ids, TopK& top) {
  while (mask != 0) {
    const int l = __builtin_ctz(mask);
    top.offer(ids[l], d[l]);
    mask &= mask - 1;
  }
}

void scanSse2(const CandidateBlock& b, float qx, float qy, float qz, TopK& top) {
  const __m128 px = _mm_set1_ps(qx), py = _mm_set1_ps(qy), pz = _mm_set1_ps(qz);
  alignas(16) float d[4];
  for (std::size_t j = 0; j < b.size; j += 4) {
    const __m128 ex = _mm_sub_ps(_mm_loadu_ps(b.x + j), px);
    const __m128 ey = _mm_sub_ps(_mm_loadu_ps(b.y + j), py);
    const __m128 ez = _mm_sub_ps(_mm_loadu_ps(b.z + j), pz);
    const __m128 d2 = _mm_add_ps(_mm_add_ps(_mm_mul_ps(ex, ex), _mm_mul_ps(ey, ey)), _mm_mul_ps(ez, ez));
    const auto mask = static_cast<unsigned>(_mm_movemask_ps(_mm_cmplt_ps(d2, _mm_set1_ps(top.worst))));
    if (mask == 0) continue;
    _mm_store_ps(d, d2);
    offerLanes(mask, d, b.ids + j, top);
  }
}

// target("avx2") only, not "fma": the compiler must not contract the products and sums.
[[gnu::target("avx2"), gnu::always_inline]] inline __m256 squaredDistancesAvx2(const CandidateBlock& b, std::size_t j,
                                                                              __m256 px, __m256 py, __m256 pz) {
  const __m256 ex = _mm256_sub_ps(_mm256_loadu_ps(b.x + j), px);
  const __m256 ey = _mm256_sub_ps(_mm256_loadu_ps(b.y + j), py);
  const __m256 ez = _mm256_sub_ps(_mm256_loadu_ps(b.z + j), pz);
  return _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(ex, ex), _mm256_mul_ps(ey, ey)), _mm256_mul_ps(ez, ez));
}

[[gnu::target("avx2")]] void scanAvx2(const CandidateBlock& b, float qx, float qy, float qz, TopK& top) {
  const __m256 px = _mm256_set1_ps(qx), py = _mm256_set1_ps(qy), pz = _mm256_set1_ps(qz);
  alignas(32) float d[8];
  for (std::size_t j = 0; j < b.size; j += 8) {
    const __m256 d2 = squaredDistancesAvx2(b, j, px, py, pz);
    const auto mask =
        static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(d2, _mm256_set1_ps(top.worst), _CMP_LT_OQ)));
    if (mask == 0) continue;
    _mm256_store_ps(d, d2);
    offerLanes(mask, d, b.ids + j, top);
  }
}

// For k ≤ 16 the k best live in registers: two of distances, two of ids, lane l holding rank l (lanes
// ≥ k are scratch, never read back). An offer's rank is how many kept distances are ≤ it (after equal
// ones, so the first offered wins, as in TopK); lanes above the rank take their lower neighbour's value,
// without a branch. TopK's insertion loop mispredicts about once per offer.
[[gnu::target("avx2")]] void scanAvx2Registers(const CandidateBlock& b, float qx, float qy, float qz, TopK& top) {
  constexpr float kInf = std::numeric_limits<float>::infinity();
  alignas(32) float kept_d[16];
  alignas(32) std::uint32_t kept_i[16];
  for (std::size_t l = 0; l < 16; ++l) {
    kept_d[l] = l < top.count ? top.out[l].sq_distance : kInf;
    kept_i[l] = l < top.count ? top.out[l].index : 0;
  }
  __m256 d0 = _mm256_load_ps(kept_d), d1 = _mm256_load_ps(kept_d + 8);
  __m256i i0 = _mm256_load_si256(reinterpret_cast<const __m256i*>(kept_i));
  __m256i i1 = _mm256_load_si256(reinterpret_cast<const __m256i*>(kept_i + 8));
  const unsigned counted = (1U << top.k) - 1U;  // lanes below k
  const __m256i lanes0 = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  const __m256i lanes1 = _mm256_setr_epi32(8, 9, 10, 11, 12, 13, 14, 15);
  const __m256i from_below = _mm256_setr_epi32(0, 0, 1, 2, 3, 4, 5, 6);
  const __m256i top_lane = _mm256_set1_epi32(7);
  const __m256i kth_lane = _mm256_set1_epi32(static_cast<int>((top.k - 1) & 7U));
  const bool kth_high = top.k > 8;
  const __m256 px = _mm256_set1_ps(qx), py = _mm256_set1_ps(qy), pz = _mm256_set1_ps(qz);
  float bound = top.worst;  // the caller's bound, then the k-th distance once there are k
  std::size_t count = top.count;
  alignas(32) float d[8];
  for (std::size_t j = 0; j < b.size; j += 8) {
    const __m256 d2 = squaredDistancesAvx2(b, j, px, py, pz);
    auto mask = static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(d2, _mm256_set1_ps(bound), _CMP_LT_OQ)));
    if (mask == 0) continue;
    _mm256_store_ps(d, d2);
    while (mask != 0) {
      const int l = __builtin_ctz(mask);
      mask &= mask - 1;
      const float dist = d[l];
      if (!(dist < bound)) continue;  // an earlier lane of the group tightened it
      const __m256 dv = _mm256_set1_ps(dist);
      const unsigned at_or_below = (static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(d0, dv, _CMP_LE_OQ))) |
                                    static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(d1, dv, _CMP_LE_OQ))) << 8) &
                                   counted;
      const __m256i rank = _mm256_set1_epi32(__builtin_popcount(at_or_below));
      const __m256i id = _mm256_set1_epi32(static_cast<int>(b.ids[j + static_cast<std::size_t>(l)]));
      // Shifted up by one lane; lane 8 takes lane 7.
      const __m256 sd0 = _mm256_permutevar8x32_ps(d0, from_below);
      const __m256 sd1 = _mm256_blend_ps(_mm256_permutevar8x32_ps(d1, from_below),
                                         _mm256_permutevar8x32_ps(d0, top_lane), 0x01);
      const __m256i si0 = _mm256_permutevar8x32_epi32(i0, from_below);
      const __m256i si1 = _mm256_blend_epi32(_mm256_permutevar8x32_epi32(i1, from_below),
                                             _mm256_permutevar8x32_epi32(i0, top_lane), 0x01);
      const __m256i above0 = _mm256_cmpgt_epi32(lanes0, rank), at0 = _mm256_cmpeq_epi32(lanes0, rank);
      const __m256i above1 = _mm256_cmpgt_epi32(lanes1, rank), at1 = _mm256_cmpeq_epi32(lanes1, rank);
      d0 = _mm256_blendv_ps(_mm256_blendv_ps(d0, sd0, _mm256_castsi256_ps(above0)), dv, _mm256_castsi256_ps(at0));
      d1 = _mm256_blendv_ps(_mm256_blendv_ps(d1, sd1, _mm256_castsi256_ps(above1)), dv, _mm256_castsi256_ps(at1));
      i0 = _mm256_blendv_epi8(_mm256_blendv_epi8(i0, si0, above0), id, at0);
      i1 = _mm256_blendv_epi8(_mm256_blendv_epi8(i1, si1, above1), id, at1);
      ++count;
      // Lane k−1 is +inf until k are kept, and then below the bound.
      bound = std::min(bound, _mm256_cvtss_f32(_mm256_permutevar8x32_ps(kth_high ? d1 : d0, kth_lane)));
    }
  }
  _mm256_store_ps(kept_d, d0);
  _mm256_store_ps(kept_d + 8, d1);
  _mm256_store_si256(reinterpret_cast<__m256i*>(kept_i), i0);
  _mm256_store_si256(reinterpret_cast<__m256i*>(kept_i + 8), i1);
  top.count = std::min(count, top.k);
  for (std::size_t l = 0; l < top.count; ++l) top.out[l] = {kept_i[l], kept_d[l]};
  top.worst = bound;
}

[[gnu::target("avx2")]] void scanAvx2Any(const CandidateBlock& b, float qx, float qy, float qz, TopK& top) {
  if (top.k <= 16) {
    scanAvx2Registers(b, qx, qy, qz, top);
  } else {
    scanAvx2(b, qx, qy, qz, top);
  }
}

#endif

}  // namespace

CandidateScanPath fastestCandidateScanPath() {
#if defined(__x86_64__)
  return cpuHasAvx2() ? CandidateScanPath::kAvx2 : CandidateScanPath::kSse2;
#else
  return CandidateScanPath::kScalar;
#endif
}

CandidateScan candidateScan(CandidateScanPath path) {
#if defined(__x86_64__)
  if (path == CandidateScanPath::kAvx2 && cpuHasAvx2()) return scanAvx2Any;
  if (path != CandidateScanPath::kScalar) return scanSse2;
#else
  (void)path;
#endif
  return scanScalar;
}

}  // namespace rigcal::registration::detail
