#include "offset_sums.hpp"

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "cpu_features.hpp"

namespace rigcal::registration::detail {

void offsetSumsScalar(const Eigen::Vector4d* points, const Neighbor* nb, std::size_t found,
                      const Eigen::Vector4d& origin, OffsetSums* out) {
  double sx = 0, sy = 0, sz = 0, sxx = 0, sxy = 0, sxz = 0, syy = 0, syz = 0, szz = 0;
  for (std::size_t j = 0; j < found; ++j) {
    const Eigen::Vector3d d = points[nb[j].index].head<3>() - origin.head<3>();
    sx += d.x();
    sy += d.y();
    sz += d.z();
    sxx += d.x() * d.x();
    sxy += d.x() * d.y();
    sxz += d.x() * d.z();
    syy += d.y() * d.y();
    syz += d.y() * d.z();
    szz += d.z() * d.z();
  }
  *out = OffsetSums{{sx, sy, sz, 0}, {sxx, sxy, sxz, 0}, {syy, syz, szz, 0}};
}

#if defined(__x86_64__)
namespace {

// target("avx2") only, not "fma": the compiler must not contract the products and sums.
[[gnu::target("avx2")]] void offsetSumsAvx2(const Eigen::Vector4d* points, const Neighbor* nb, std::size_t found,
                                            const Eigen::Vector4d& origin, OffsetSums* out) {
  const __m256d o = _mm256_loadu_pd(origin.data());
  __m256d s = _mm256_setzero_pd(), x = s, yz = s;
  for (std::size_t j = 0; j < found; ++j) {
    const __m256d d = _mm256_sub_pd(_mm256_loadu_pd(points[nb[j].index].data()), o);
    s = _mm256_add_pd(s, d);
    x = _mm256_add_pd(x, _mm256_mul_pd(_mm256_permute4x64_pd(d, 0x00), d));  // (x, x, x, x)·d
    // (y, y, z, w)·(y, z, z, w): yy, yz, zz
    yz = _mm256_add_pd(yz, _mm256_mul_pd(_mm256_permute4x64_pd(d, 0xE5), _mm256_permute4x64_pd(d, 0xE9)));
  }
  _mm256_storeu_pd(out->s, s);
  _mm256_storeu_pd(out->x, x);
  _mm256_storeu_pd(out->yz, yz);
  out->s[3] = out->x[3] = out->yz[3] = 0.0;
}

}  // namespace
#endif

OffsetSumsKernel fastestOffsetSums() {
#if defined(__x86_64__)
  if (cpuHasAvx2()) return offsetSumsAvx2;
#endif
  return offsetSumsScalar;
}

}  // namespace rigcal::registration::detail
