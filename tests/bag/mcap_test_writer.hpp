#pragma once
// A minimal MCAP writer for tests that need files rosbag2 does not produce: several chunks, lz4,
// overlapping chunk times, no summary. Records as in https://mcap.dev/spec; compression by libzstd/liblz4.
#include <lz4frame.h>
#include <zstd.h>

#include <cstdint>
#include <cstring>
#include <fstream>
#include <filesystem>
#include <string>
#include <vector>

#include "rigcal/bag/crc32.hpp"

namespace rigcal::bag::test {

struct TestMessage {
  std::uint16_t channel = 1;  // 1: /a, 2: /b
  std::uint64_t log_time = 0;
  std::vector<std::uint8_t> data;
};

class McapTestWriter {
 public:
  using Bytes = std::vector<std::uint8_t>;

  static void put(Bytes& b, const void* p, std::size_t n) {
    const auto* c = static_cast<const std::uint8_t*>(p);
    b.insert(b.end(), c, c + n);
  }
  template <class T>
  static void put(Bytes& b, T v) { put(b, &v, sizeof v); }
  static void putString(Bytes& b, const std::string& s) {
    put(b, std::uint32_t(s.size()));
    put(b, s.data(), s.size());
  }
  static void record(Bytes& out, std::uint8_t opcode, const Bytes& body) {
    put(out, opcode);
    put(out, std::uint64_t(body.size()));
    put(out, body.data(), body.size());
  }

  static Bytes schemaAndChannels() {
    Bytes out, s, a, b;
    put(s, std::uint16_t(1));
    putString(s, "std_msgs/msg/String");
    putString(s, "ros2msg");
    putString(s, "string data");
    record(out, 0x03, s);
    for (auto [id, topic] : {std::pair<std::uint16_t, const char*>{1, "/a"}, {2, "/b"}}) {
      Bytes c;
      put(c, id);
      put(c, std::uint16_t(1));
      putString(c, topic);
      putString(c, "cdr");
      put(c, std::uint32_t(0));  // empty metadata map
      record(out, 0x04, c);
    }
    return out;
  }

  /// Appends one chunk holding `messages` (and the schema/channels), compressed as named.
  void addChunk(const std::vector<TestMessage>& messages, const std::string& compression = "") {
    Bytes records = schemaAndChannels();
    std::uint64_t lo = ~0ull, hi = 0;
    for (const auto& m : messages) {
      Bytes body;
      put(body, m.channel);
      put(body, std::uint32_t(0));
      put(body, m.log_time);
      put(body, m.log_time);
      put(body, m.data.data(), m.data.size());
      record(records, 0x05, body);
      lo = std::min(lo, m.log_time);
      hi = std::max(hi, m.log_time);
    }
    Bytes packed = records;
    if (compression == "zstd") {
      packed.resize(ZSTD_compressBound(records.size()));
      packed.resize(ZSTD_compress(packed.data(), packed.size(), records.data(), records.size(), 3));
    } else if (compression == "lz4") {
      packed.resize(LZ4F_compressFrameBound(records.size(), nullptr));
      packed.resize(LZ4F_compressFrame(packed.data(), packed.size(), records.data(), records.size(), nullptr));
    }
    Bytes chunk;
    put(chunk, lo);
    put(chunk, hi);
    put(chunk, std::uint64_t(records.size()));
    put(chunk, crc32Update(0, records));
    putString(chunk, compression);
    put(chunk, std::uint64_t(packed.size()));
    put(chunk, packed.data(), packed.size());
    chunks_.push_back({lo, hi, data_.size(), chunk.size() + 9, compression, packed.size(), records.size()});
    record(data_, 0x06, chunk);
  }

  /// The whole file; with_summary adds schema, channels and chunk indexes after Data End.
  [[nodiscard]] Bytes bytes(bool with_summary) const {
    Bytes out(std::begin(kMagicBytes), std::end(kMagicBytes));
    Bytes header;
    putString(header, "ros2");
    putString(header, "rigcal-test");
    record(out, 0x01, header);
    const std::uint64_t data_start = out.size();
    out.insert(out.end(), data_.begin(), data_.end());
    Bytes data_end;
    put(data_end, crc32Update(0, out));
    record(out, 0x0F, data_end);
    std::uint64_t summary_start = 0;
    if (with_summary) {
      summary_start = out.size();
      const Bytes sc = schemaAndChannels();
      out.insert(out.end(), sc.begin(), sc.end());
      for (const auto& c : chunks_) {
        Bytes index;
        put(index, c.lo);
        put(index, c.hi);
        put(index, data_start + c.offset);
        put(index, std::uint64_t(c.length));
        put(index, std::uint32_t(0));  // message index offsets: none
        put(index, std::uint64_t(0));
        putString(index, c.compression);
        put(index, std::uint64_t(c.compressed));
        put(index, std::uint64_t(c.uncompressed));
        record(out, 0x08, index);
      }
    }
    Bytes footer;
    put(footer, summary_start);
    put(footer, std::uint64_t(0));
    put(footer, std::uint32_t(0));
    record(out, 0x02, footer);
    out.insert(out.end(), std::begin(kMagicBytes), std::end(kMagicBytes));
    return out;
  }

  static void save(const std::filesystem::path& path, const Bytes& bytes) {
    std::ofstream(path, std::ios::binary).write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  }

 private:
  static constexpr std::uint8_t kMagicBytes[8] = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
  struct ChunkInfo {
    std::uint64_t lo, hi;
    std::size_t offset, length;
    std::string compression;
    std::size_t compressed, uncompressed;
  };
  Bytes data_;
  std::vector<ChunkInfo> chunks_;
};

}  // namespace rigcal::bag::test
