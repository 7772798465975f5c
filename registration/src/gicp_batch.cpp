#include "gicp_batch.hpp"

#include <algorithm>
#include <iterator>

#include "cpu_features.hpp"

namespace rigcal::registration::detail {

namespace {

// kLanes doubles: one AVX register in the AVX2 build, two SSE2 registers in the baseline one; operators
// work lane by lane. Read in place from the (8-byte aligned) columns, by reference: passing a 32-byte
// vector by value would differ between the two builds' ABIs.
constexpr std::size_t kLanes = 4;
using Lanes = double __attribute__((vector_size(8 * kLanes), aligned(8), may_alias));
const Lanes& lanes(const double* p) { return *reinterpret_cast<const Lanes*>(p); }

// Index of H(r, c), r <= c, in the row-major upper triangle.
constexpr int upper(int r, int c) { return r * 6 - r * (r - 1) / 2 + (c - r); }
constexpr int kB = 21, kCost = 27;

// The batch's columns, as plain pointers for the file-local arithmetic below.
struct Columns {
  const double (*q)[GicpBatch::kCapacity];
  const double (*r)[GicpBatch::kCapacity];
  const double (*a)[GicpBatch::kCapacity];
  const double (*base)[GicpBatch::kCapacity];
  const double* mask;
  Sym3* const* out;
  std::size_t n;
};

// The arithmetic, written once and compiled twice: for x86-64's baseline and for AVX2 (inlined into a
// target("avx2") function). Dispatched by hand, once, rather than by an ifunc (target_clones), whose
// resolver runs before the sanitizers' runtimes are up.
[[gnu::always_inline]] inline void accumulateLanes(const Columns& c, double (*sums)[kLanes]) {
  Lanes s[28];
  for (int k = 0; k < 28; ++k) s[k] = lanes(sums[k]);
  for (std::size_t i = 0; i < c.n; i += kLanes) {
    const Lanes qx = lanes(c.q[0] + i), qy = lanes(c.q[1] + i), qz = lanes(c.q[2] + i);
    const Lanes ax = lanes(c.a[0] + i), ay = lanes(c.a[1] + i), az = lanes(c.a[2] + i);
    // C = base − a·aᵀ and W = C⁻¹ by cofactors, the mask zeroing padding.
    const Lanes f00 = lanes(c.base[0] + i) - ax * ax, f01 = lanes(c.base[1] + i) - ax * ay;
    const Lanes f02 = lanes(c.base[2] + i) - ax * az, f11 = lanes(c.base[3] + i) - ay * ay;
    const Lanes f12 = lanes(c.base[4] + i) - ay * az, f22 = lanes(c.base[5] + i) - az * az;
    const Lanes c00 = f11 * f22 - f12 * f12, c01 = f02 * f12 - f01 * f22, c02 = f01 * f12 - f02 * f11;
    const Lanes c11 = f00 * f22 - f02 * f02, c12 = f01 * f02 - f00 * f12, c22 = f00 * f11 - f01 * f01;
    const Lanes scale = lanes(c.mask + i) / (f00 * c00 + f01 * c01 + f02 * c02);
    const Lanes w00 = c00 * scale, w01 = c01 * scale, w02 = c02 * scale;
    const Lanes w11 = c11 * scale, w12 = c12 * scale, w22 = c22 * scale;
    for (std::size_t l = 0; l < kLanes; ++l) *c.out[i + l] = {w00[l], w01[l], w02[l], w11[l], w12[l], w22[l]};
    // u = W·r; V = W·[q]× column by column (as addWeightedHessian).
    const Lanes rx = lanes(c.r[0] + i), ry = lanes(c.r[1] + i), rz = lanes(c.r[2] + i);
    const Lanes ux = w00 * rx + w01 * ry + w02 * rz;
    const Lanes uy = w01 * rx + w11 * ry + w12 * rz;
    const Lanes uz = w02 * rx + w12 * ry + w22 * rz;
    const Lanes v0x = w01 * qz - w02 * qy, v0y = w11 * qz - w12 * qy, v0z = w12 * qz - w22 * qy;
    const Lanes v1x = w02 * qx - w00 * qz, v1y = w12 * qx - w01 * qz, v1z = w22 * qx - w02 * qz;
    const Lanes v2x = w00 * qy - w01 * qx, v2y = w01 * qy - w11 * qx, v2z = w02 * qy - w12 * qx;
    s[upper(0, 0)] += w00;
    s[upper(0, 1)] += w01;
    s[upper(0, 2)] += w02;
    s[upper(1, 1)] += w11;
    s[upper(1, 2)] += w12;
    s[upper(2, 2)] += w22;
    s[upper(0, 3)] -= v0x;
    s[upper(1, 3)] -= v0y;
    s[upper(2, 3)] -= v0z;
    s[upper(0, 4)] -= v1x;
    s[upper(1, 4)] -= v1y;
    s[upper(2, 4)] -= v1z;
    s[upper(0, 5)] -= v2x;
    s[upper(1, 5)] -= v2y;
    s[upper(2, 5)] -= v2z;
    s[upper(3, 3)] += qz * v0y - qy * v0z;
    s[upper(3, 4)] += qz * v1y - qy * v1z;
    s[upper(3, 5)] += qz * v2y - qy * v2z;
    s[upper(4, 4)] += qx * v1z - qz * v1x;
    s[upper(4, 5)] += qx * v2z - qz * v2x;
    s[upper(5, 5)] += qy * v2x - qx * v2y;
    s[kB + 0] += ux;
    s[kB + 1] += uy;
    s[kB + 2] += uz;
    s[kB + 3] += qy * uz - qz * uy;
    s[kB + 4] += qz * ux - qx * uz;
    s[kB + 5] += qx * uy - qy * ux;
    s[kCost] += rx * ux + ry * uy + rz * uz;
  }
  for (int k = 0; k < 28; ++k) __builtin_memcpy(sums[k], &s[k], sizeof s[k]);
}

void accumulateBaseline(const Columns& c, double (*sums)[kLanes]) { accumulateLanes(c, sums); }
[[gnu::target("avx2")]] void accumulateAvx2(const Columns& c, double (*sums)[kLanes]) { accumulateLanes(c, sums); }

}  // namespace

bool GicpBatch::avx2Available() { return cpuHasAvx2(); }

GicpBatch::GicpBatch(GicpLanes lanes) : avx2_(lanes != GicpLanes::kBaseline && cpuHasAvx2()) {}

void GicpBatch::run() {
  while (n_ % kLanes != 0) {  // pad to whole lanes with matches that contribute nothing
    const std::size_t i = n_++;
    for (auto* column : {q_, r_, a_}) column[0][i] = column[1][i] = column[2][i] = 0.0;
    for (int k = 0; k < 6; ++k) base_[k][i] = (k == 0 || k == 3 || k == 5) ? 1.0 : 0.0;
    mask_[i] = 0.0;
    out_[i] = &discard_;
  }
  const Columns columns{q_, r_, a_, base_, mask_, out_, n_};
  if (avx2_) {
    accumulateAvx2(columns, sums_);
  } else {
    accumulateBaseline(columns, sums_);
  }
  n_ = 0;
}

void GicpBatch::finish(LinearSystem& sys) {
  if (n_ > 0) run();
  const auto total = [&](int k) { return (sums_[k][0] + sums_[k][1]) + (sums_[k][2] + sums_[k][3]); };
  for (int r = 0; r < 6; ++r) {
    for (int c = r; c < 6; ++c) sys.H(r, c) += total(upper(r, c));
  }
  for (int k = 0; k < 6; ++k) sys.b[k] += total(kB + k);
  sys.cost += total(kCost);
  for (auto& s : sums_) std::fill(std::begin(s), std::end(s), 0.0);
}

}  // namespace rigcal::registration::detail
