#pragma once
// MCAP records (https://mcap.dev/spec, major version 0): opcodes, the fields rigcal uses, and the
// splitting of a byte range into <u8 opcode><u64 length><body> records. Parsers take a record body and
// throw BagError naming `what` (file and record offset) when a field runs past the body.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace rigcal::bag::mcap {

inline constexpr std::array<std::uint8_t, 8> kMagic = {0x89, 'M', 'C', 'A', 'P', '0', '\r', '\n'};
inline constexpr std::size_t kRecordHeaderSize = 9;  // opcode + u64 body length

enum class Opcode : std::uint8_t {
  kHeader = 0x01,
  kFooter = 0x02,
  kSchema = 0x03,
  kChannel = 0x04,
  kMessage = 0x05,
  kChunk = 0x06,
  kMessageIndex = 0x07,
  kChunkIndex = 0x08,
  kAttachment = 0x09,
  kAttachmentIndex = 0x0A,
  kStatistics = 0x0B,
  kMetadata = 0x0C,
  kMetadataIndex = 0x0D,
  kSummaryOffset = 0x0E,
  kDataEnd = 0x0F,
};

struct RecordView {
  std::uint8_t opcode = 0;
  std::size_t offset = 0;  // of the opcode byte, within the split range
  std::span<const std::uint8_t> body;
};

/// Walks back-to-back records in memory (a decompressed chunk, the summary section).
class RecordSplitter {
 public:
  RecordSplitter(std::span<const std::uint8_t> bytes, std::string what) : bytes_(bytes), what_(std::move(what)) {}
  /// The next record, nullopt at the end; throws BagError when a record runs past the range.
  std::optional<RecordView> next();

 private:
  std::span<const std::uint8_t> bytes_;
  std::string what_;
  std::size_t pos_ = 0;
};

struct SchemaRecord {
  std::uint16_t id = 0;
  std::string name, encoding;
};

struct ChannelRecord {
  std::uint16_t id = 0, schema_id = 0;
  std::string topic, message_encoding;
};

struct MessageRecord {
  std::uint16_t channel_id = 0;
  std::uint32_t sequence = 0;
  std::uint64_t log_time = 0, publish_time = 0;
  std::span<const std::uint8_t> data;
};

struct ChunkRecord {
  std::uint64_t message_start_time = 0, message_end_time = 0, uncompressed_size = 0;
  std::uint32_t uncompressed_crc = 0;  // 0: not computed
  std::string compression;             // "", "zstd" or "lz4"
  std::span<const std::uint8_t> records;
};

struct ChunkIndexRecord {
  std::uint64_t message_start_time = 0, message_end_time = 0, chunk_start_offset = 0, chunk_length = 0;
  std::string compression;
  std::uint64_t compressed_size = 0, uncompressed_size = 0;
};

struct FooterRecord {
  std::uint64_t summary_start = 0, summary_offset_start = 0;
  std::uint32_t summary_crc = 0;
};
inline constexpr std::size_t kFooterBodySize = 20;

SchemaRecord parseSchema(std::span<const std::uint8_t> body, std::string_view what);
ChannelRecord parseChannel(std::span<const std::uint8_t> body, std::string_view what);
MessageRecord parseMessage(std::span<const std::uint8_t> body, std::string_view what);
ChunkRecord parseChunk(std::span<const std::uint8_t> body, std::string_view what);
ChunkIndexRecord parseChunkIndex(std::span<const std::uint8_t> body, std::string_view what);
FooterRecord parseFooter(std::span<const std::uint8_t> body, std::string_view what);
/// Data End: the CRC-32 of the data section (0: not computed).
std::uint32_t parseDataEnd(std::span<const std::uint8_t> body, std::string_view what);

}  // namespace rigcal::bag::mcap
