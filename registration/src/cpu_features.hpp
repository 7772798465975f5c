#pragma once
// Private: what the CPU running us can do, asked once. The kernels with an AVX2 build (gicp_batch,
// candidate_scan, offset_sums) pick it here at run time rather than through target_clones, whose ifunc
// resolver crashes TSan binaries at start-up.

namespace rigcal::registration::detail {

/// True when AVX2 instructions may run (always false off x86-64).
inline bool cpuHasAvx2() {
#if defined(__x86_64__)
  static const bool avx2 = [] {
    __builtin_cpu_init();
    return __builtin_cpu_supports("avx2") != 0;
  }();
  return avx2;
#else
  return false;
#endif
}

}  // namespace rigcal::registration::detail
