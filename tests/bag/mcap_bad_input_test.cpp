// MCAP streaming and bad input: chunks merged in log-time order with and without a summary (lz4, zstd,
// stored), and corrupted copies of rosbag2's own files: truncated (what came before the cut is used,
// with a warning), bad CRC, unknown compression, a chunk that does not decompress, an empty bag. Each
// error is one line naming the file and the record offset.
#include <gtest/gtest.h>

#include <cstring>
#include <fstream>
#include <iterator>

#include "mcap_test_writer.hpp"
#include "rigcal/bag/bag.hpp"
#include "rigcal/bag/bag_error.hpp"
#include "rigcal/bag/mcap_file.hpp"
#include "test_data.hpp"

namespace rigcal::bag {
namespace {

using test::McapTestWriter;
using test::TestMessage;
using Bytes = std::vector<std::uint8_t>;

Bytes readBytes(const std::filesystem::path& p) {
  std::ifstream in(p, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>()};
}

// Offsets of the Chunk records, found by walking the records after the magic.
std::vector<std::size_t> chunkOffsets(const Bytes& b) {
  std::vector<std::size_t> out;
  for (std::size_t p = 8; p + 9 <= b.size();) {
    std::uint64_t length;
    std::memcpy(&length, b.data() + p + 1, 8);
    if (b[p] == 0x06) out.push_back(p);
    if (b[p] == 0x02) break;
    p += 9 + std::size_t(length);
  }
  return out;
}

std::size_t firstChunkOffset(const Bytes& b) {
  const auto all = chunkOffsets(b);
  if (all.empty()) ADD_FAILURE() << "no chunk";
  return all.empty() ? 0 : all.front();
}

// Offset of a chunk's records field (after start, end, size, crc, compression string, records length).
std::size_t chunkRecordsOffset(const Bytes& b, std::size_t chunk) {
  std::uint32_t compression_length;
  std::memcpy(&compression_length, b.data() + chunk + 9 + 28, 4);
  return chunk + 9 + 32 + compression_length + 8;
}

struct Delivered {
  std::vector<std::pair<TimeNs, std::string>> messages;  // time, topic + payload
  std::vector<std::string> warnings;
};

Delivered readAll(const std::filesystem::path& path) {
  Bag bag(path);
  Delivered d;
  while (const auto m = bag.next())
  {
    std::string text = bag.topics()[m->topic].name;
    text += ':';
    text.append(m->data.begin(), m->data.end());
    d.messages.emplace_back(m->log_time_ns, std::move(text));
  }
  d.warnings = bag.warnings();
  return d;
}

std::string errorOf(const std::filesystem::path& path) {
  try {
    readAll(path);
  } catch (const BagError& e) {
    EXPECT_EQ(std::string(e.what()).find('\n'), std::string::npos) << "one line: " << e.what();
    return e.what();
  }
  ADD_FAILURE() << path << ": expected a BagError";
  return {};
}

TestMessage msg(std::uint16_t channel, std::uint64_t t) {
  std::string text = "m";
  text += std::to_string(t);
  return {channel, t, Bytes(text.begin(), text.end())};
}

// Three chunks whose time ranges overlap, each compressed differently, delivered as one ordered stream.
McapTestWriter overlappingChunks() {
  McapTestWriter w;
  w.addChunk({msg(1, 10), msg(2, 40), msg(1, 30)}, "zstd");  // unsorted inside the chunk too
  w.addChunk({msg(2, 20), msg(1, 50)}, "lz4");
  w.addChunk({msg(1, 35), msg(2, 60)}, "");
  return w;
}

TEST(McapReader, OverlappingChunksComeOutInLogTimeOrderWithOrWithoutSummary) {
  rigcal::test::TempDir dir;
  const auto w = overlappingChunks();
  McapTestWriter::save(dir / "indexed.mcap", w.bytes(true));
  McapTestWriter::save(dir / "linear.mcap", w.bytes(false));
  EXPECT_TRUE(McapFile(dir / "indexed.mcap").indexed());
  EXPECT_FALSE(McapFile(dir / "linear.mcap").indexed());
  const auto indexed = readAll(dir / "indexed.mcap");
  const auto linear = readAll(dir / "linear.mcap");
  std::vector<TimeNs> times;
  for (const auto& m : indexed.messages) times.push_back(m.first);
  EXPECT_EQ(times, (std::vector<TimeNs>{10, 20, 30, 35, 40, 50, 60}));
  EXPECT_EQ(indexed.messages[1].second, "/b:m20");
  EXPECT_EQ(indexed.messages, linear.messages);
  EXPECT_TRUE(indexed.warnings.empty());
  EXPECT_TRUE(linear.warnings.empty()) << linear.warnings.front();
}

// Streaming: a long bag of time-ordered chunks holds one or two chunks at a time, whatever its length;
// overlapping chunks are held together only while they overlap.
TEST(McapReader, MemoryHoldsOnlyTheChunksOverlappingTheCurrentMessage) {
  rigcal::test::TempDir dir;
  McapTestWriter sequential;
  for (std::uint64_t c = 0; c < 200; ++c) sequential.addChunk({msg(1, c * 10), msg(2, c * 10 + 5)}, c % 2 ? "zstd" : "lz4");
  McapTestWriter::save(dir / "long.mcap", sequential.bytes(true));
  McapFile file(dir / "long.mcap");
  std::size_t n = 0;
  while (file.next()) ++n;
  EXPECT_EQ(n, 400u);
  EXPECT_EQ(file.chunkCount(), 200u);
  EXPECT_LE(file.peakLoadedChunks(), 2u);

  McapFile overlapping_file = [&] {
    McapTestWriter::save(dir / "overlap.mcap", overlappingChunks().bytes(true));
    return McapFile(dir / "overlap.mcap");
  }();
  while (overlapping_file.next()) {
  }
  EXPECT_EQ(overlapping_file.peakLoadedChunks(), 3u) << "all three chunks overlap in time";
}

TEST(McapReader, TruncatedFileDeliversTheChunksBeforeTheCutWithAWarning) {
  rigcal::test::TempDir dir;
  McapTestWriter w;
  w.addChunk({msg(1, 1), msg(2, 2)}, "zstd");
  w.addChunk({msg(1, 3)}, "lz4");
  w.addChunk({msg(1, 4), msg(2, 5)}, "zstd");
  const Bytes bytes = w.bytes(true);
  const auto chunks = chunkOffsets(bytes);
  ASSERT_EQ(chunks.size(), 3u);
  Bytes cut(bytes.begin(), bytes.begin() + long(chunks[2] + 40));  // inside the third chunk
  McapTestWriter::save(dir / "cut.mcap", cut);
  const auto d = readAll(dir / "cut.mcap");
  ASSERT_EQ(d.messages.size(), 3u) << "the first two chunks are used";
  EXPECT_EQ(d.messages.back().second, "/a:m3");
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_NE(d.warnings[0].find("cut.mcap: truncated at offset " + std::to_string(chunks[2])), std::string::npos)
      << d.warnings[0];
  EXPECT_NE(d.warnings[0].find("2 chunks"), std::string::npos) << d.warnings[0];
}

TEST(McapReader, TruncatedRosbag2FileWarnsInsteadOfFailing) {
  RIGCAL_REQUIRE_DATA(talker, "bags/rosbag2/mcap_talker/talker.mcap");
  rigcal::test::TempDir dir;
  Bytes bytes = readBytes(talker);
  const std::size_t chunk = firstChunkOffset(bytes);
  bytes.resize(chunk + 100);
  McapTestWriter::save(dir / "talker.mcap", bytes);
  const auto d = readAll(dir / "talker.mcap");
  EXPECT_TRUE(d.messages.empty()) << "its only chunk was cut";
  ASSERT_EQ(d.warnings.size(), 1u);
  EXPECT_NE(d.warnings[0].find("truncated at offset " + std::to_string(chunk)), std::string::npos) << d.warnings[0];
}

TEST(McapReader, BadChunkCrcNamesFileAndChunkOffset) {
  RIGCAL_REQUIRE_DATA(talker, "bags/rosbag2/mcap_talker/talker.mcap");
  rigcal::test::TempDir dir;
  Bytes bytes = readBytes(talker);
  const std::size_t chunk = firstChunkOffset(bytes);
  bytes[chunk + 9 + 24] ^= 0x01;  // the chunk's stored uncompressed CRC
  McapTestWriter::save(dir / "bad_crc.mcap", bytes);
  const std::string e = errorOf(dir / "bad_crc.mcap");
  EXPECT_NE(e.find("bad_crc.mcap: chunk at offset " + std::to_string(chunk)), std::string::npos) << e;
  EXPECT_NE(e.find("chunk CRC mismatch"), std::string::npos) << e;
}

// The next chunk is read and inflated on a second thread ahead of the reader: a bad chunk half-way through
// an indexed file still comes out as its own error when the reader reaches it, after every message
// before it, never earlier and never lost.
TEST(McapReader, ABadChunkHalfWayFailsWhereTheReaderReachesIt) {
  rigcal::test::TempDir dir;
  McapTestWriter sequential;
  for (std::uint64_t c = 0; c < 40; ++c) sequential.addChunk({msg(1, c * 10), msg(2, c * 10 + 5)}, c % 2 ? "zstd" : "lz4");
  Bytes bytes = sequential.bytes(true);
  const std::size_t bad = chunkOffsets(bytes).at(20);
  bytes[bad + 9 + 24] ^= 0x01;  // its stored uncompressed CRC
  McapTestWriter::save(dir / "bad_half_way.mcap", bytes);
  Bag bag(dir / "bad_half_way.mcap");
  std::vector<TimeNs> times;
  try {
    while (const auto m = bag.next()) times.push_back(m->log_time_ns);
    ADD_FAILURE() << "the bad chunk was not reported";
  } catch (const BagError& e) {
    EXPECT_NE(std::string(e.what()).find("chunk at offset " + std::to_string(bad) + ": chunk CRC mismatch"),
              std::string::npos)
        << e.what();
  }
  ASSERT_EQ(times.size(), 40u) << "the 20 chunks before it, two messages each";
  EXPECT_EQ(times.back(), TimeNs(19 * 10 + 5));
}

// Without a summary the file is walked record by record and the Data End's CRC of the data section is
// checked: a flipped bit outside any chunk's own CRC (a chunk's start-time field) is caught there.
TEST(McapReader, BadDataSectionCrcNamesFileAndDataEndOffset) {
  rigcal::test::TempDir dir;
  McapTestWriter w;
  w.addChunk({msg(1, 1), msg(2, 2)}, "");
  w.addChunk({msg(1, 3)}, "zstd");
  Bytes bytes = w.bytes(false);
  McapTestWriter::save(dir / "good.mcap", bytes);
  EXPECT_EQ(readAll(dir / "good.mcap").messages.size(), 3u) << "the writer's data CRC is accepted";
  const auto chunks = chunkOffsets(bytes);
  ASSERT_EQ(chunks.size(), 2u);
  bytes[chunks[1] + 9] ^= 0x01;  // the second chunk's message_start_time
  std::size_t data_end = 0;
  for (std::size_t p = 8; p + 9 <= bytes.size();) {
    std::uint64_t length;
    std::memcpy(&length, bytes.data() + p + 1, 8);
    if (bytes[p] == 0x0F) data_end = p;
    p += 9 + std::size_t(length);
  }
  McapTestWriter::save(dir / "bad_data.mcap", bytes);
  const std::string e = errorOf(dir / "bad_data.mcap");
  EXPECT_NE(e.find("bad_data.mcap: record at offset " + std::to_string(data_end)), std::string::npos) << e;
  EXPECT_NE(e.find("data section CRC mismatch"), std::string::npos) << e;
}

TEST(McapReader, BadSummaryCrcNamesFileAndFooterOffset) {
  RIGCAL_REQUIRE_DATA(cdr, "bags/rosbag2/mcap_cdr_test/cdr_test_0.mcap");
  rigcal::test::TempDir dir;
  Bytes bytes = readBytes(cdr);
  std::uint64_t summary_start;
  const std::size_t footer = bytes.size() - 8 - 29;
  std::memcpy(&summary_start, bytes.data() + footer + 9, 8);
  bytes[std::size_t(summary_start) + 20] ^= 0x01;  // inside the summary's first record
  McapTestWriter::save(dir / "bad_summary.mcap", bytes);
  const std::string e = errorOf(dir / "bad_summary.mcap");
  EXPECT_NE(e.find("bad_summary.mcap: record at offset " + std::to_string(footer)), std::string::npos) << e;
  EXPECT_NE(e.find("summary CRC mismatch"), std::string::npos) << e;
}

TEST(McapReader, UnknownCompressionNamesFileAndChunkOffset) {
  RIGCAL_REQUIRE_DATA(talker, "bags/rosbag2/mcap_talker/talker.mcap");
  rigcal::test::TempDir dir;
  Bytes bytes = readBytes(talker);
  const std::size_t chunk = firstChunkOffset(bytes);
  ASSERT_EQ(std::string(bytes.begin() + long(chunk + 9 + 32), bytes.begin() + long(chunk + 9 + 36)), "zstd");
  bytes[chunk + 9 + 35] = 'x';
  McapTestWriter::save(dir / "zstx.mcap", bytes);
  const std::string e = errorOf(dir / "zstx.mcap");
  EXPECT_NE(e.find("zstx.mcap: chunk at offset " + std::to_string(chunk)), std::string::npos) << e;
  EXPECT_NE(e.find("unknown compression 'zstx'"), std::string::npos) << e;
}

TEST(McapReader, ChunkThatDoesNotDecompressNamesFileAndChunkOffset) {
  RIGCAL_REQUIRE_DATA(talker, "bags/rosbag2/mcap_talker/talker.mcap");
  rigcal::test::TempDir dir;
  Bytes bytes = readBytes(talker);
  const std::size_t chunk = firstChunkOffset(bytes);
  const std::size_t records = chunkRecordsOffset(bytes, chunk);
  for (std::size_t i = 0; i < 4; ++i) bytes[records + i] = 0;  // the zstd frame magic
  McapTestWriter::save(dir / "garbled.mcap", bytes);
  const std::string e = errorOf(dir / "garbled.mcap");
  EXPECT_NE(e.find("garbled.mcap: chunk at offset " + std::to_string(chunk)), std::string::npos) << e;
  EXPECT_NE(e.find("zstd chunk does not decompress"), std::string::npos) << e;

  // lz4 too: a frame cut in half inside an intact record.
  McapTestWriter w;
  w.addChunk({msg(1, 1), msg(1, 2)}, "lz4");
  Bytes lz4 = w.bytes(true);
  const std::size_t lz4_chunk = firstChunkOffset(lz4);
  lz4[chunkRecordsOffset(lz4, lz4_chunk) + 4] ^= 0xFF;  // frame descriptor flags
  McapTestWriter::save(dir / "garbled_lz4.mcap", lz4);
  const std::string e2 = errorOf(dir / "garbled_lz4.mcap");
  EXPECT_NE(e2.find("garbled_lz4.mcap: chunk at offset " + std::to_string(lz4_chunk)), std::string::npos) << e2;
  EXPECT_NE(e2.find("lz4 chunk does not decompress"), std::string::npos) << e2;
}

TEST(McapReader, EmptyBagsAreOneLineErrorsNamingThePath) {
  rigcal::test::TempDir dir;
  std::filesystem::create_directories(dir / "empty_folder");
  const std::string folder = errorOf(dir / "empty_folder");
  EXPECT_NE(folder.find("empty_folder: empty bag"), std::string::npos) << folder;
  McapTestWriter::save(dir / "zero.mcap", {});
  const std::string zero = errorOf(dir / "zero.mcap");
  EXPECT_NE(zero.find("zero.mcap: empty file"), std::string::npos) << zero;
  const std::string missing = errorOf(dir / "missing.mcap");
  EXPECT_NE(missing.find("missing.mcap: no such bag"), std::string::npos) << missing;
}

}  // namespace
}  // namespace rigcal::bag
