#include "rigcal/drivers/hesai/hesai_crc.hpp"

#include <array>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

namespace rigcal::drivers::hesai {
namespace {

// Slicing-by-16 tables for the non-reflected CRC-32/MPEG-2: t[s][i] is the CRC register after
// byte i followed by s zero bytes.
struct CrcTables {
  std::array<std::array<std::uint32_t, 256>, 16> t{};
  CrcTables() {
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i << 24;
      for (int k = 0; k < 8; ++k) c = (c & 0x80000000u) ? (c << 1) ^ 0x04C11DB7u : (c << 1);
      t[0][i] = c;
    }
    for (std::uint32_t i = 0; i < 256; ++i)
      for (int s = 1; s < 16; ++s) t[s][i] = (t[s - 1][i] << 8) ^ t[0][t[s - 1][i] >> 24];
  }
};
const CrcTables& crcTables() {
  static const CrcTables tables;
  return tables;
}

std::uint32_t crcTable(std::uint32_t c, const std::uint8_t* p, std::size_t n) {
  const auto& t = crcTables().t;
  while (n >= 16) {
    const std::uint32_t a = c ^ ((std::uint32_t(p[0]) << 24) | (std::uint32_t(p[1]) << 16) |
                                 (std::uint32_t(p[2]) << 8) | std::uint32_t(p[3]));
    c = t[15][a >> 24] ^ t[14][(a >> 16) & 0xFF] ^ t[13][(a >> 8) & 0xFF] ^ t[12][a & 0xFF] ^ t[11][p[4]] ^
        t[10][p[5]] ^ t[9][p[6]] ^ t[8][p[7]] ^ t[7][p[8]] ^ t[6][p[9]] ^ t[5][p[10]] ^ t[4][p[11]] ^
        t[3][p[12]] ^ t[2][p[13]] ^ t[1][p[14]] ^ t[0][p[15]];
    p += 16;
    n -= 16;
  }
  while (n--) c = (c << 8) ^ t[0][((c >> 24) ^ *p++) & 0xFF];
  return c;
}

#if defined(__x86_64__)
// Carry-less multiplication folding (the method of Intel's "Fast CRC Computation for Generic
// Polynomials Using PCLMULQDQ", non-reflected form): 16 bytes at a time are folded into a 128-bit
// remainder with x^192 mod P and x^128 mod P; the last remainder and the tail bytes go through the
// table. Used when the CPU has PCLMULQDQ and SSSE3.
std::uint64_t xPowModP(int n) {
  std::uint64_t r = 1;
  for (int i = 0; i < n; ++i) {
    r <<= 1;
    if (r & (std::uint64_t(1) << 32)) r ^= 0x104C11DB7ull;
  }
  return r;
}

__attribute__((target("pclmul,ssse3"))) std::uint32_t crcFold(const std::uint8_t* p, std::size_t n) {
  static const __m128i k = _mm_set_epi64x(static_cast<long long>(xPowModP(192)), static_cast<long long>(xPowModP(128)));
  const __m128i swap = _mm_set_epi8(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  __m128i x = _mm_shuffle_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)), swap);
  x = _mm_xor_si128(x, _mm_set_epi32(-1, 0, 0, 0));  // the initial register 0xFFFFFFFF
  p += 16;
  n -= 16;
  while (n >= 16) {
    const __m128i next = _mm_shuffle_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)), swap);
    x = _mm_xor_si128(_mm_xor_si128(_mm_clmulepi64_si128(x, k, 0x11), _mm_clmulepi64_si128(x, k, 0x00)), next);
    p += 16;
    n -= 16;
  }
  alignas(16) std::uint8_t rest[16];
  _mm_store_si128(reinterpret_cast<__m128i*>(rest), _mm_shuffle_epi8(x, swap));
  return crcTable(crcTable(0, rest, 16), p, n);
}

bool haveClmul() {
  static const bool have = __builtin_cpu_supports("pclmul") && __builtin_cpu_supports("ssse3");
  return have;
}
#endif

}  // namespace

std::uint32_t crc32Mpeg2(std::span<const std::uint8_t> bytes) {
#if defined(__x86_64__)
  if (bytes.size() >= 64 && haveClmul()) return crcFold(bytes.data(), bytes.size());
#endif
  return crcTable(0xFFFFFFFFu, bytes.data(), bytes.size());
}

}  // namespace rigcal::drivers::hesai
