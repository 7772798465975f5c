#include "candidate_scan.hpp"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

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
[[gnu::target("avx2")]] void scanAvx2(const CandidateBlock& b, float qx, float qy, float qz, TopK& top) {
  const __m256 px = _mm256_set1_ps(qx), py = _mm256_set1_ps(qy), pz = _mm256_set1_ps(qz);
  alignas(32) float d[8];
  for (std::size_t j = 0; j < b.size; j += 8) {
    const __m256 ex = _mm256_sub_ps(_mm256_loadu_ps(b.x + j), px);
    const __m256 ey = _mm256_sub_ps(_mm256_loadu_ps(b.y + j), py);
    const __m256 ez = _mm256_sub_ps(_mm256_loadu_ps(b.z + j), pz);
    const __m256 d2 =
        _mm256_add_ps(_mm256_add_ps(_mm256_mul_ps(ex, ex), _mm256_mul_ps(ey, ey)), _mm256_mul_ps(ez, ez));
    const auto mask =
        static_cast<unsigned>(_mm256_movemask_ps(_mm256_cmp_ps(d2, _mm256_set1_ps(top.worst), _CMP_LT_OQ)));
    if (mask == 0) continue;
    _mm256_store_ps(d, d2);
    offerLanes(mask, d, b.ids + j, top);
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
  if (path == CandidateScanPath::kAvx2 && cpuHasAvx2()) return scanAvx2;
  if (path != CandidateScanPath::kScalar) return scanSse2;
#else
  (void)path;
#endif
  return scanScalar;
}

}  // namespace rigcal::registration::detail
