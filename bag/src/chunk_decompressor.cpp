#include "rigcal/bag/chunk_decompressor.hpp"

#include <lz4frame.h>
#include <zstd.h>

#include <memory>
#include <string>

#include "rigcal/bag/bag_error.hpp"
#include "rigcal/bag/crc32.hpp"

namespace rigcal::bag::mcap {

struct ChunkDecompressor::Contexts {
  std::unique_ptr<ZSTD_DCtx, decltype(&ZSTD_freeDCtx)> zstd{nullptr, &ZSTD_freeDCtx};
  std::unique_ptr<LZ4F_dctx, decltype(&LZ4F_freeDecompressionContext)> lz4{nullptr, &LZ4F_freeDecompressionContext};
};

namespace {

void inflateZstd(ZSTD_DCtx& ctx, std::span<const std::uint8_t> in, std::span<std::uint8_t> out,
                 std::string_view what) {
  const std::size_t n = ZSTD_decompressDCtx(&ctx, out.data(), out.size(), in.data(), in.size());
  if (ZSTD_isError(n))
    throw BagError(std::string(what) + ": zstd chunk does not decompress: " + ZSTD_getErrorName(n));
  if (n != out.size())
    throw BagError(std::string(what) + ": zstd chunk inflates to " + std::to_string(n) + " bytes, declared " +
                   std::to_string(out.size()));
}

void inflateLz4(LZ4F_dctx& ctx, std::span<const std::uint8_t> in, std::span<std::uint8_t> out,
                std::string_view what) {
  LZ4F_resetDecompressionContext(&ctx);  // a previous chunk may have failed mid-frame
  std::size_t in_pos = 0, out_pos = 0;
  while (true) {
    std::size_t in_size = in.size() - in_pos, out_size = out.size() - out_pos;
    const std::size_t hint = LZ4F_decompress(&ctx, out.data() + out_pos, &out_size, in.data() + in_pos,
                                             &in_size, nullptr);
    if (LZ4F_isError(hint))
      throw BagError(std::string(what) + ": lz4 chunk does not decompress: " + LZ4F_getErrorName(hint));
    in_pos += in_size;
    out_pos += out_size;
    if (hint == 0) break;  // frame complete
    if (in_size == 0 && out_size == 0)
      throw BagError(std::string(what) + ": lz4 chunk ends inside its frame (" + std::to_string(out_pos) +
                     " of " + std::to_string(out.size()) + " bytes inflated)");
  }
  if (out_pos != out.size())
    throw BagError(std::string(what) + ": lz4 chunk inflates to " + std::to_string(out_pos) + " bytes, declared " +
                   std::to_string(out.size()));
}

// The declared size must be one the compressed bytes can produce: zstd frames usually record their
// content size, and lz4 cannot expand more than 255:1.
void checkDeclaredSize(const ChunkRecord& chunk, std::string_view what) {
  if (chunk.compression == "zstd") {
    const unsigned long long content = ZSTD_getFrameContentSize(chunk.records.data(), chunk.records.size());
    if (content == ZSTD_CONTENTSIZE_ERROR)
      throw BagError(std::string(what) + ": zstd chunk does not decompress: no valid zstd frame header");
    if (content != ZSTD_CONTENTSIZE_UNKNOWN && content != chunk.uncompressed_size)
      throw BagError(std::string(what) + ": zstd frame holds " + std::to_string(content) + " bytes, chunk declares " +
                     std::to_string(chunk.uncompressed_size));
  } else if (chunk.uncompressed_size > std::uint64_t(chunk.records.size()) * 255 + 64) {
    throw BagError(std::string(what) + ": lz4 chunk of " + std::to_string(chunk.records.size()) +
                   " bytes cannot inflate to the declared " + std::to_string(chunk.uncompressed_size));
  }
}

}  // namespace

ChunkDecompressor::ChunkDecompressor() : contexts_(std::make_unique<Contexts>()) {}

ChunkDecompressor::~ChunkDecompressor() = default;

std::span<const std::uint8_t> ChunkDecompressor::inflate(const ChunkRecord& chunk, PageBuffer& buffer,
                                                         std::string_view what) {
  std::span<const std::uint8_t> records;
  if (chunk.compression.empty()) {
    records = chunk.records;
  } else {
    if (chunk.compression != "zstd" && chunk.compression != "lz4")
      throw BagError(std::string(what) + ": unknown compression '" + chunk.compression + "' (zstd, lz4 or none)");
    if (chunk.uncompressed_size > kMaxChunkBytes)
      throw BagError(std::string(what) + ": chunk declares " + std::to_string(chunk.uncompressed_size) +
                     " uncompressed bytes, more than the " + std::to_string(kMaxChunkBytes) + " accepted");
    checkDeclaredSize(chunk, what);  // before allocating what a corrupt header claims
    const auto out = buffer.resize(std::size_t(chunk.uncompressed_size));
    if (chunk.compression == "zstd") {
      if (!contexts_->zstd) contexts_->zstd.reset(ZSTD_createDCtx());
      if (!contexts_->zstd) throw BagError(std::string(what) + ": cannot create a zstd context");
      inflateZstd(*contexts_->zstd, chunk.records, out, what);
    } else {
      if (!contexts_->lz4) {
        LZ4F_dctx* raw = nullptr;
        if (LZ4F_isError(LZ4F_createDecompressionContext(&raw, LZ4F_VERSION)))
          throw BagError(std::string(what) + ": cannot create an lz4 context");
        contexts_->lz4.reset(raw);
      }
      inflateLz4(*contexts_->lz4, chunk.records, out, what);
    }
    records = out;
  }
  if (records.size() != chunk.uncompressed_size)
    throw BagError(std::string(what) + ": chunk holds " + std::to_string(records.size()) + " bytes, declares " +
                   std::to_string(chunk.uncompressed_size));
  if (chunk.uncompressed_crc != 0) {
    const std::uint32_t crc = crc32Update(0, records);
    if (crc != chunk.uncompressed_crc)
      throw BagError(std::string(what) + ": chunk CRC mismatch (stored " + std::to_string(chunk.uncompressed_crc) +
                     ", computed " + std::to_string(crc) + ")");
  }
  return records;
}

}  // namespace rigcal::bag::mcap
