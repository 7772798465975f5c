#pragma once
// Copies between private memory and a slot. The shared side is touched only through std::atomic_ref, word by
// word: release stores on the writer's side, acquire loads on the reader's (see ring_protocol.hpp for why).
// A running checksum is folded into the same pass, so verifying a scan costs no second sweep over it. Its
// state is copied into locals for the loop: kept behind a reference, every release store (or acquire load)
// would force it out to memory and back, and the copy would run at 2 GB/s instead of memcpy speed.
#include <atomic>
#include <cstddef>
#include <cstdint>
#include <cstring>

namespace rigcal::shm::detail {

/// A two-sum (Fletcher-like) checksum over 64-bit words; order-sensitive, cheap enough to run at copy speed.
struct Checksum {
  std::uint64_t a = 0;
  std::uint64_t b = 0;
  void add(std::uint64_t word) {
    a += word;
    b += a;
  }
  [[nodiscard]] std::uint64_t value() const { return b ^ (a * 0x9e3779b97f4a7c15ULL); }
};

inline std::atomic_ref<std::uint64_t> sharedWord(std::byte* p) {
  return std::atomic_ref<std::uint64_t>(*reinterpret_cast<std::uint64_t*>(p));
}

/// `n` bytes from private `src` to shared `dst` (8-byte aligned).
inline void copyToShared(std::byte* dst, const void* src, std::size_t n, Checksum& sum) {
  const auto* s = static_cast<const unsigned char*>(src);
  const std::size_t words = n / 8;
  Checksum local = sum;
  for (std::size_t i = 0; i < words; ++i) {
    std::uint64_t w;
    std::memcpy(&w, s + 8 * i, 8);
    local.add(w);
    sharedWord(dst + 8 * i).store(w, std::memory_order_release);
  }
  sum = local;
  if (const std::size_t tail = n - 8 * words; tail != 0) {
    std::uint64_t w = 0;
    for (std::size_t j = 0; j < tail; ++j) {
      const unsigned char c = s[8 * words + j];
      w |= std::uint64_t{c} << (8 * j);
      std::atomic_ref<std::byte>(dst[8 * words + j]).store(std::byte{c}, std::memory_order_release);
    }
    sum.add(w);
  }
}

/// `n` bytes from shared `src` (8-byte aligned) to private `dst`.
inline void copyFromShared(void* dst, std::byte* src, std::size_t n, Checksum& sum) {
  auto* d = static_cast<unsigned char*>(dst);
  const std::size_t words = n / 8;
  Checksum local = sum;
  for (std::size_t i = 0; i < words; ++i) {
    const std::uint64_t w = sharedWord(src + 8 * i).load(std::memory_order_acquire);
    local.add(w);
    std::memcpy(d + 8 * i, &w, 8);
  }
  sum = local;
  if (const std::size_t tail = n - 8 * words; tail != 0) {
    std::uint64_t w = 0;
    for (std::size_t j = 0; j < tail; ++j) {
      const auto c = static_cast<unsigned char>(
          std::atomic_ref<std::byte>(src[8 * words + j]).load(std::memory_order_acquire));
      w |= std::uint64_t{c} << (8 * j);
      d[8 * words + j] = c;
    }
    sum.add(w);
  }
}

}  // namespace rigcal::shm::detail
