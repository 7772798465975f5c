#pragma once
// Private: GICP's per-match arithmetic (fused covariance, its inverse, the Gauss–Newton blocks) for a
// batch of matches at a time, four matches per instruction. The matching loop is branchy and scalar; this
// part is ~170 flops per match with no branches, so it is gathered into columns and run in four lanes:
// AVX2 where the CPU has it, else x86-64's baseline SSE2 (two instructions per step), chosen once at run
// time. Both do the same IEEE operations in the same order (no FMA contraction), so results do not
// depend on the CPU, nor on the thread count (batches never cross the solver's chunks).
#include <cstddef>

#include <Eigen/Core>

#include "kernels.hpp"
#include "solver.hpp"

namespace rigcal::registration::detail {

/// Which build of the arithmetic a batch runs: the best the CPU has, or the baseline (tests compare them).
enum class GicpLanes { kBest, kBaseline };

class GicpBatch {
 public:
  explicit GicpBatch(GicpLanes lanes = GicpLanes::kBest);
  /// Whether kBest is the AVX2 build on this CPU (else it is the baseline).
  static bool avx2Available();

  static constexpr std::size_t kCapacity = 32;  // matches per run: a multiple of the 4 lanes

  /// One match: q = T·p in the target frame, r = q − t, and its fused covariance C = base − a·aᵀ
  /// (rank-one source: base = C_t + I, a = R·v; general source: base = C_t + R·C_s·Rᵀ, a = 0). C⁻¹ is
  /// written to *weight when the batch runs (the cost pass reuses it).
  void add(const Eigen::Vector3d& q, const Eigen::Vector3d& r, const Sym3& base, const Eigen::Vector3d& a,
           Sym3* weight) {
    const std::size_t i = n_++;
    q_[0][i] = q.x(), q_[1][i] = q.y(), q_[2][i] = q.z();
    r_[0][i] = r.x(), r_[1][i] = r.y(), r_[2][i] = r.z();
    a_[0][i] = a.x(), a_[1][i] = a.y(), a_[2][i] = a.z();
    base_[0][i] = base.xx, base_[1][i] = base.xy, base_[2][i] = base.xz;
    base_[3][i] = base.yy, base_[4][i] = base.yz, base_[5][i] = base.zz;
    mask_[i] = 1.0;
    out_[i] = weight;
    if (n_ == kCapacity) run();
  }

  /// Adds everything added since the last finish() to sys (H's upper triangle, b, cost) and resets.
  void finish(LinearSystem& sys);

 private:
  void run();  // the batch so far into the lane sums

  alignas(32) double q_[3][kCapacity];
  alignas(32) double r_[3][kCapacity];
  alignas(32) double a_[3][kCapacity];
  alignas(32) double base_[6][kCapacity];
  alignas(32) double mask_[kCapacity];  // 0 for the padding of a partial lane group
  Sym3* out_[kCapacity];
  Sym3 discard_;  // the padding's weight
  bool avx2_ = false;  // which build of the arithmetic run() uses
  std::size_t n_ = 0;
  // H's 21 upper entries (row-major), b's 6, the cost: four lanes each.
  alignas(32) double sums_[28][4] = {};
};

}  // namespace rigcal::registration::detail
