#pragma once
// CRC-32 (IEEE 802.3, reflected polynomial 0xEDB88320), the checksum MCAP stores for chunks, the data
// section and the summary. Incremental: crc32Update(crc32Update(0, a), b) == crc32 of a then b.
#include <cstdint>
#include <span>

namespace rigcal::bag {

std::uint32_t crc32Update(std::uint32_t crc, std::span<const std::uint8_t> bytes);

}  // namespace rigcal::bag
