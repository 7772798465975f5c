#pragma once
// The CRC the Hesai protocols 6.1 and 3.2 put in their packets (table-driven, or folded with carry-less
// multiplication where the CPU has it: the check runs on every packet).
#include <cstdint>
#include <span>

namespace rigcal::drivers::hesai {

/// CRC-32/MPEG-2 (poly 0x04C11DB7, init 0xFFFFFFFF, no reflection, no final xor).
std::uint32_t crc32Mpeg2(std::span<const std::uint8_t> bytes);


}  // namespace rigcal::drivers::hesai
