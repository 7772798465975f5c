#pragma once
// Inflates an MCAP chunk's records ("" stored, "zstd", "lz4" frame) and checks their CRC-32. Errors
// (unknown compression, a stream that does not inflate to the declared size, CRC mismatch) throw
// BagError prefixed with `what` (file and chunk offset).
#include <cstdint>
#include <span>
#include <string_view>
#include <vector>

#include "rigcal/bag/mcap_records.hpp"

namespace rigcal::bag::mcap {

/// A chunk claiming more than this uncompressed is refused rather than allocated (writers use ~1 MB).
inline constexpr std::uint64_t kMaxChunkBytes = std::uint64_t(1) << 31;

/// The chunk's uncompressed records: a view of the record itself when stored uncompressed, else `buffer`.
std::span<const std::uint8_t> inflateChunk(const ChunkRecord& chunk, std::vector<std::uint8_t>& buffer,
                                           std::string_view what);

}  // namespace rigcal::bag::mcap
