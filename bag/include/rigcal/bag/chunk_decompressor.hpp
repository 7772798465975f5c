#pragma once
// Inflates an MCAP chunk's records ("" stored, "zstd", "lz4" frame) and checks their CRC-32. Errors
// (unknown compression, a stream that does not inflate to the declared size, CRC mismatch) throw
// BagError prefixed with `what` (file and chunk offset). The zstd and lz4 contexts live as long as the
// decompressor: a reader inflates hundreds of chunks and a fresh zstd context is ~100 kB of setup each.
#include <cstdint>
#include <memory>
#include <span>
#include <string_view>

#include "rigcal/bag/mcap_records.hpp"
#include "rigcal/bag/page_buffer.hpp"

namespace rigcal::bag::mcap {

/// A chunk claiming more than this uncompressed is refused rather than allocated (writers use ~1 MB).
inline constexpr std::uint64_t kMaxChunkBytes = std::uint64_t(1) << 31;

class ChunkDecompressor {
 public:
  ChunkDecompressor();
  ~ChunkDecompressor();
  ChunkDecompressor(const ChunkDecompressor&) = delete;
  ChunkDecompressor& operator=(const ChunkDecompressor&) = delete;

  /// The chunk's uncompressed records: a view of the record itself when stored uncompressed, else of
  /// `buffer`, which zstd and lz4 inflate into directly.
  std::span<const std::uint8_t> inflate(const ChunkRecord& chunk, PageBuffer& buffer, std::string_view what);

 private:
  struct Contexts;
  std::unique_ptr<Contexts> contexts_;
};

}  // namespace rigcal::bag::mcap
