// The MCAP reader's chunk buffers and decompression contexts, reused from chunk to chunk: a mapping
// that keeps its bytes until it must grow, and contexts that inflate correctly after a chunk failed.
#include <gtest/gtest.h>
#include <lz4frame.h>
#include <unistd.h>
#include <zstd.h>

#include <algorithm>
#include <numeric>
#include <vector>

#include "rigcal/bag/bag_error.hpp"
#include "rigcal/bag/chunk_decompressor.hpp"
#include "rigcal/bag/crc32.hpp"
#include "rigcal/bag/page_buffer.hpp"

namespace rigcal::bag {
namespace {

TEST(PageBuffer, GrowsByWholePagesAtLeastDoublingAndKeepsBytesWhileItFits) {
  const std::size_t page = std::size_t(::sysconf(_SC_PAGESIZE));
  PageBuffer buffer;
  EXPECT_EQ(buffer.capacity(), 0u);
  auto bytes = buffer.resize(100);
  ASSERT_EQ(bytes.size(), 100u);
  EXPECT_EQ(buffer.capacity(), page);
  std::iota(bytes.begin(), bytes.end(), std::uint8_t(1));
  const auto* where = bytes.data();

  bytes = buffer.resize(page);  // still fits: same mapping, same bytes
  EXPECT_EQ(bytes.data(), where);
  EXPECT_EQ(bytes[0], 1);
  EXPECT_EQ(bytes[99], 100);

  buffer.resize(page + 1);  // must grow: at least twice the old capacity
  EXPECT_EQ(buffer.capacity(), 2 * page);
  buffer.resize(5 * page + 7);  // more than double asked: exactly enough pages
  EXPECT_EQ(buffer.capacity(), 6 * page);
  EXPECT_EQ(buffer.size(), 5 * page + 7);

  PageBuffer moved = std::move(buffer);
  EXPECT_EQ(moved.capacity(), 6 * page);
  EXPECT_EQ(buffer.capacity(), 0u);  // NOLINT(bugprone-use-after-move): the moved-from state is defined
}

std::vector<std::uint8_t> someRecords(std::size_t n) {
  std::vector<std::uint8_t> r(n);
  for (std::size_t i = 0; i < n; ++i) r[i] = std::uint8_t((i * 7) ^ (i >> 5));
  return r;
}

std::vector<std::uint8_t> compress(const std::string& compression, const std::vector<std::uint8_t>& in) {
  std::vector<std::uint8_t> out;
  if (compression == "zstd") {
    out.resize(ZSTD_compressBound(in.size()));
    out.resize(ZSTD_compress(out.data(), out.size(), in.data(), in.size(), 3));
  } else {
    out.resize(LZ4F_compressFrameBound(in.size(), nullptr));
    out.resize(LZ4F_compressFrame(out.data(), out.size(), in.data(), in.size(), nullptr));
  }
  return out;
}

class ReusedDecompressor : public ::testing::TestWithParam<const char*> {};

TEST_P(ReusedDecompressor, InflatesEveryChunkAfterOneThatDidNot) {
  const std::string compression = GetParam();
  mcap::ChunkDecompressor decompressor;
  PageBuffer buffer;
  for (const std::size_t size : {std::size_t(50'000), std::size_t(3'000), std::size_t(400'000)}) {
    const auto records = someRecords(size);
    auto packed = compress(compression, records);
    mcap::ChunkRecord chunk;
    chunk.compression = compression;
    chunk.uncompressed_size = records.size();
    chunk.uncompressed_crc = crc32Update(0, records);

    // The same frame cut in half first: it must fail, and must not spoil the context for the next.
    const std::vector<std::uint8_t> cut(packed.begin(), packed.begin() + std::ptrdiff_t(packed.size() / 2));
    chunk.records = cut;
    EXPECT_THROW(decompressor.inflate(chunk, buffer, "cut chunk"), BagError) << compression << " " << size;

    chunk.records = packed;
    const auto inflated = decompressor.inflate(chunk, buffer, "whole chunk");
    ASSERT_EQ(inflated.size(), records.size());
    EXPECT_TRUE(std::equal(inflated.begin(), inflated.end(), records.begin())) << compression << " " << size;
  }
}

INSTANTIATE_TEST_SUITE_P(Compressions, ReusedDecompressor, ::testing::Values("zstd", "lz4"));

}  // namespace
}  // namespace rigcal::bag
