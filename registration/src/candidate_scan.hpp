#pragma once
// Private: cell_knn.cpp's inner loop. One query against the candidates of a 3x3x3 block of cells: their
// squared distances, and each that beats the TopK's current bound offered to it, in candidate order.
// The SIMD paths compute 4 (SSE2) or 8 (AVX2) distances and one comparison mask at a time instead of a
// distance array then a scalar filter. Every path does the same float operations in the same order
// ((dx² + dy²) + dz², never a fused multiply-add) and offers in the same order, so all give the scalar
// loop's answer bit for bit. The AVX2 path also keeps up to 16 best in registers instead of TopK's
// array, inserting without a branch (same ranks and ties).
#include <cstddef>
#include <cstdint>

#include "top_k.hpp"

namespace rigcal::registration::detail {

/// Candidate arrays are padded to a multiple of this; padding lies at +inf, so it never beats a bound.
inline constexpr std::size_t kCandidateLanes = 8;

struct CandidateBlock {
  const float* x;  // relative to the block's centre, one array per axis
  const float* y;
  const float* z;
  const std::uint32_t* ids;
  std::size_t size;  // a multiple of kCandidateLanes
};

enum class CandidateScanPath { kScalar, kSse2, kAvx2 };
using CandidateScan = void (*)(const CandidateBlock& block, float qx, float qy, float qz, TopK& top);

/// AVX2 where the CPU has it, else SSE2 (x86-64's baseline), else the scalar loop. Chosen once.
CandidateScanPath fastestCandidateScanPath();
/// The scan of that path; a path the CPU lacks falls back to the next slower one.
CandidateScan candidateScan(CandidateScanPath path);

}  // namespace rigcal::registration::detail
