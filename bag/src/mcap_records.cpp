#include "rigcal/bag/mcap_records.hpp"

#include "rigcal/bag/bag_error.hpp"
#include "rigcal/bag/byte_cursor.hpp"

namespace rigcal::bag::mcap {

namespace {
std::string hexByte(std::uint8_t b) {
  static constexpr char kDigits[] = "0123456789abcdef";
  return {'0', 'x', kDigits[b >> 4], kDigits[b & 15]};
}
}  // namespace

std::optional<RecordView> RecordSplitter::next() {
  if (pos_ == bytes_.size()) return std::nullopt;
  ByteCursor header(bytes_.subspan(pos_), what_);
  if (header.remaining() < kRecordHeaderSize)
    throw BagError(what_ + ": record header at byte " + std::to_string(pos_) + " cut short (" +
                   std::to_string(header.remaining()) + " bytes left)");
  RecordView record;
  record.offset = pos_;
  record.opcode = header.read<std::uint8_t>();
  const auto length = header.read<std::uint64_t>();
  if (length > header.remaining())
    throw BagError(what_ + ": record (opcode " + hexByte(record.opcode) + ") at byte " +
                   std::to_string(pos_) + " claims " + std::to_string(length) + " bytes, " +
                   std::to_string(header.remaining()) + " left");
  record.body = header.take(std::size_t(length));
  pos_ += kRecordHeaderSize + std::size_t(length);
  return record;
}

SchemaRecord parseSchema(std::span<const std::uint8_t> body, std::string_view what) {
  ByteCursor c(body, what);
  SchemaRecord s;
  s.id = c.read<std::uint16_t>();
  s.name = c.readString();
  s.encoding = c.readString();
  return s;  // the schema text itself (u32 length + bytes) is not needed: layouts are built in
}

ChannelRecord parseChannel(std::span<const std::uint8_t> body, std::string_view what) {
  ByteCursor c(body, what);
  ChannelRecord ch;
  ch.id = c.read<std::uint16_t>();
  ch.schema_id = c.read<std::uint16_t>();
  ch.topic = c.readString();
  ch.message_encoding = c.readString();
  return ch;  // metadata map follows; unused
}

MessageRecord parseMessage(std::span<const std::uint8_t> body, std::string_view what) {
  ByteCursor c(body, what);
  MessageRecord m;
  m.channel_id = c.read<std::uint16_t>();
  m.sequence = c.read<std::uint32_t>();
  m.log_time = c.read<std::uint64_t>();
  m.publish_time = c.read<std::uint64_t>();
  m.data = c.rest();
  return m;
}

ChunkRecord parseChunk(std::span<const std::uint8_t> body, std::string_view what) {
  ByteCursor c(body, what);
  ChunkRecord k;
  k.message_start_time = c.read<std::uint64_t>();
  k.message_end_time = c.read<std::uint64_t>();
  k.uncompressed_size = c.read<std::uint64_t>();
  k.uncompressed_crc = c.read<std::uint32_t>();
  k.compression = c.readString();
  const auto records_length = c.read<std::uint64_t>();
  if (records_length > c.remaining())
    throw BagError(std::string(what) + ": chunk records claim " + std::to_string(records_length) + " bytes, " +
                   std::to_string(c.remaining()) + " in the record");
  k.records = c.take(std::size_t(records_length));
  return k;
}

ChunkIndexRecord parseChunkIndex(std::span<const std::uint8_t> body, std::string_view what) {
  ByteCursor c(body, what);
  ChunkIndexRecord k;
  k.message_start_time = c.read<std::uint64_t>();
  k.message_end_time = c.read<std::uint64_t>();
  k.chunk_start_offset = c.read<std::uint64_t>();
  k.chunk_length = c.read<std::uint64_t>();
  const auto map_length = c.read<std::uint32_t>();
  c.take(map_length);  // message index offsets: we read whole chunks, not per-channel indexes
  c.read<std::uint64_t>();  // message_index_length
  k.compression = c.readString();
  k.compressed_size = c.read<std::uint64_t>();
  k.uncompressed_size = c.read<std::uint64_t>();
  return k;
}

FooterRecord parseFooter(std::span<const std::uint8_t> body, std::string_view what) {
  ByteCursor c(body, what);
  FooterRecord f;
  f.summary_start = c.read<std::uint64_t>();
  f.summary_offset_start = c.read<std::uint64_t>();
  f.summary_crc = c.read<std::uint32_t>();
  return f;
}

std::uint32_t parseDataEnd(std::span<const std::uint8_t> body, std::string_view what) {
  ByteCursor c(body, what);
  return c.read<std::uint32_t>();
}

}  // namespace rigcal::bag::mcap
