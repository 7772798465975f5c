#include "rigcal/bag/crc32.hpp"

#include <zlib.h>

#include <algorithm>

namespace rigcal::bag {

// zlib's CRC-32 is the same checksum, several times faster than a byte-wise table (it was the bulk of the
// time reading an uncompressed MCAP).
std::uint32_t crc32Update(std::uint32_t crc, std::span<const std::uint8_t> bytes) {
  uLong c = crc;
  while (!bytes.empty()) {
    const std::size_t n = std::min<std::size_t>(bytes.size(), 1u << 30);  // zlib takes uInt lengths
    c = ::crc32(c, bytes.data(), uInt(n));
    bytes = bytes.subspan(n);
  }
  return std::uint32_t(c);
}

}  // namespace rigcal::bag
