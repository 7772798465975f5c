#pragma once
// A streaming MCAP writer (https://mcap.dev/spec, major version 0): messages are gathered into chunks
// (zstd-compressed or stored) of about `chunk_bytes`, each followed by its per-channel message indexes;
// the summary holds schemas, channels, statistics and chunk indexes, with summary offsets; the chunk,
// data-section and summary CRCs are written. Memory holds one chunk. The file is written atomically: it
// appears at its name only when close() succeeds.
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <span>
#include <string>
#include <vector>

#include "rigcal/core/time.hpp"

namespace rigcal {
class AtomicFile;
}

namespace rigcal::bag {

struct McapWriterOptions {
  std::string compression = "zstd";       // "zstd" or "" (stored)
  int zstd_level = 3;
  std::size_t chunk_bytes = 1u << 20;     // a chunk is closed once its records reach this size
  bool summary = true;                    // false: readers find messages by a linear scan
  std::string profile = "ros2";
  std::string library = "rigcal";
};

class McapWriter {
 public:
  /// Throws std::runtime_error "<file>: ..." when the file cannot be created, std::invalid_argument for an
  /// unknown compression.
  explicit McapWriter(const std::filesystem::path& file, McapWriterOptions options = {});
  /// Without close() nothing is left at the file's name.
  ~McapWriter();
  McapWriter(const McapWriter&) = delete;
  McapWriter& operator=(const McapWriter&) = delete;

  /// A schema (ROS 2: name "pkg/msg/Type", encoding "ros2msg", data the .msg text); returns its id.
  std::uint16_t addSchema(const std::string& name, const std::string& encoding, const std::string& data);
  /// A channel on a topic (ROS 2: message encoding "cdr"); returns its id.
  std::uint16_t addChannel(const std::string& topic, std::uint16_t schema_id, const std::string& message_encoding = "cdr",
                           const std::map<std::string, std::string>& metadata = {});
  /// Appends a message (any time order; readers order by log time).
  void write(std::uint16_t channel_id, TimeNs log_time_ns, std::span<const std::uint8_t> data,
             TimeNs publish_time_ns = -1);
  /// Writes the last chunk, the summary and the footer, and puts the file in place.
  void close();

  [[nodiscard]] std::uint64_t messageCount() const { return message_count_; }
  [[nodiscard]] std::uint64_t chunkCount() const { return chunk_indexes_.size(); }
  [[nodiscard]] std::uint64_t bytesWritten() const { return offset_; }

 private:
  using Bytes = std::vector<std::uint8_t>;
  struct ChunkIndex {
    std::uint64_t start_time, end_time, offset, length;
    std::map<std::uint16_t, std::uint64_t> message_index_offsets;
    std::uint64_t message_index_length, compressed_size, uncompressed_size;
  };

  void emit(const Bytes& bytes, bool data_section);
  void flushChunk();

  std::filesystem::path path_;
  McapWriterOptions options_;
  std::unique_ptr<AtomicFile> file_;
  std::uint64_t offset_ = 0;
  std::uint32_t data_crc_ = 0;
  Bytes schemas_, channels_;  // their records, repeated in the summary
  std::uint16_t schema_count_ = 0, channel_count_ = 0;
  // The open chunk: its records, and per channel (log time, offset in the records) for its message index.
  Bytes chunk_;
  std::map<std::uint16_t, std::vector<std::pair<std::uint64_t, std::uint64_t>>> chunk_messages_;
  std::uint64_t chunk_start_ = 0, chunk_end_ = 0;
  Bytes compressed_;
  std::vector<ChunkIndex> chunk_indexes_;
  std::map<std::uint16_t, std::uint64_t> channel_message_counts_;
  std::map<std::uint16_t, std::uint32_t> sequences_;
  std::uint64_t message_count_ = 0, start_time_ = 0, end_time_ = 0;
  void* zstd_ = nullptr;  // ZSTD_CCtx, reused across chunks
  bool closed_ = false;
};

}  // namespace rigcal::bag
