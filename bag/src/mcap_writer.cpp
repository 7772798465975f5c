#include "rigcal/bag/mcap_writer.hpp"

#include <zstd.h>

#include <algorithm>
#include <limits>
#include <stdexcept>

#include "rigcal/bag/crc32.hpp"
#include "rigcal/bag/mcap_records.hpp"
#include "rigcal/core/atomic_file.hpp"

namespace rigcal::bag {

namespace {

using mcap::Opcode;
using Bytes = std::vector<std::uint8_t>;

template <class T>
void put(Bytes& b, T v) {
  const auto* p = reinterpret_cast<const std::uint8_t*>(&v);  // MCAP is little-endian, as our hosts
  b.insert(b.end(), p, p + sizeof v);
}
void putBytes(Bytes& b, std::span<const std::uint8_t> bytes) { b.insert(b.end(), bytes.begin(), bytes.end()); }
void putString(Bytes& b, const std::string& s) {
  put(b, std::uint32_t(s.size()));
  b.insert(b.end(), s.begin(), s.end());
}
/// Starts a record in `b`; finishRecord fills its length once the body is appended.
std::size_t beginRecord(Bytes& b, Opcode opcode) {
  put(b, std::uint8_t(opcode));
  const std::size_t at = b.size();
  put(b, std::uint64_t(0));
  return at;
}
void finishRecord(Bytes& b, std::size_t at) {
  const std::uint64_t length = b.size() - at - sizeof(std::uint64_t);
  std::copy_n(reinterpret_cast<const std::uint8_t*>(&length), sizeof length, b.begin() + std::ptrdiff_t(at));
}
/// A map<u16, u64> field: u32 byte length, then the pairs.
void putIdMap(Bytes& b, const std::map<std::uint16_t, std::uint64_t>& m) {
  put(b, std::uint32_t(m.size() * (2 + 8)));
  for (const auto& [k, v] : m) {
    put(b, k);
    put(b, v);
  }
}

}  // namespace

McapWriter::McapWriter(const std::filesystem::path& file, McapWriterOptions options)
    : path_(file), options_(std::move(options)) {
  if (options_.compression != "" && options_.compression != "zstd")
    throw std::invalid_argument(path_.string() + ": MCAP compression '" + options_.compression +
                                "' is not written (zstd or none)");
  file_ = std::make_unique<AtomicFile>(path_);
  if (options_.compression == "zstd") zstd_ = ZSTD_createCCtx();
  Bytes head(mcap::kMagic.begin(), mcap::kMagic.end());
  const auto at = beginRecord(head, Opcode::kHeader);
  putString(head, options_.profile);
  putString(head, options_.library);
  finishRecord(head, at);
  emit(head, true);
}

McapWriter::~McapWriter() { ZSTD_freeCCtx(static_cast<ZSTD_CCtx*>(zstd_)); }

void McapWriter::emit(const Bytes& bytes, bool data_section) {
  file_->stream().write(reinterpret_cast<const char*>(bytes.data()), std::streamsize(bytes.size()));
  // Data-section CRC from the file's first byte, as the reference writers compute it.
  if (data_section) data_crc_ = crc32Update(data_crc_, bytes);
  offset_ += bytes.size();
}

std::uint16_t McapWriter::addSchema(const std::string& name, const std::string& encoding, const std::string& data) {
  if (schema_count_ == std::numeric_limits<std::uint16_t>::max())
    throw std::length_error(path_.string() + ": too many MCAP schemas");
  const std::uint16_t id = ++schema_count_;  // 0 means "no schema"
  Bytes r;
  const auto at = beginRecord(r, Opcode::kSchema);
  put(r, id);
  putString(r, name);
  putString(r, encoding);
  putString(r, data);  // u32 length + bytes
  finishRecord(r, at);
  // Outside chunks, before any message that needs it: a linear reader meets it first.
  emit(r, true);
  putBytes(schemas_, r);
  return id;
}

std::uint16_t McapWriter::addChannel(const std::string& topic, std::uint16_t schema_id,
                                     const std::string& message_encoding,
                                     const std::map<std::string, std::string>& metadata) {
  if (schema_id > schema_count_)
    throw std::invalid_argument(path_.string() + ": channel " + topic + " names unknown schema " +
                                std::to_string(schema_id));
  if (channel_count_ == std::numeric_limits<std::uint16_t>::max())
    throw std::length_error(path_.string() + ": too many MCAP channels");
  const std::uint16_t id = channel_count_++;
  Bytes r;
  const auto at = beginRecord(r, Opcode::kChannel);
  put(r, id);
  put(r, schema_id);
  putString(r, topic);
  putString(r, message_encoding);
  Bytes map;
  for (const auto& [k, v] : metadata) {
    putString(map, k);
    putString(map, v);
  }
  put(r, std::uint32_t(map.size()));
  putBytes(r, map);
  finishRecord(r, at);
  emit(r, true);
  putBytes(channels_, r);
  channel_message_counts_[id] = 0;
  return id;
}

void McapWriter::write(std::uint16_t channel_id, TimeNs log_time_ns, std::span<const std::uint8_t> data,
                       TimeNs publish_time_ns) {
  if (closed_) throw std::logic_error(path_.string() + ": write after close");
  if (channel_id >= channel_count_)
    throw std::invalid_argument(path_.string() + ": message on unknown channel " + std::to_string(channel_id));
  if (log_time_ns < 0) throw std::invalid_argument(path_.string() + ": negative log time");
  const auto log_time = std::uint64_t(log_time_ns);
  if (chunk_messages_.empty()) chunk_start_ = chunk_end_ = log_time;
  chunk_start_ = std::min(chunk_start_, log_time);
  chunk_end_ = std::max(chunk_end_, log_time);
  chunk_messages_[channel_id].emplace_back(log_time, chunk_.size());
  const auto at = beginRecord(chunk_, Opcode::kMessage);
  put(chunk_, channel_id);
  put(chunk_, sequences_[channel_id]++);
  put(chunk_, log_time);
  put(chunk_, std::uint64_t(publish_time_ns < 0 ? log_time_ns : publish_time_ns));
  putBytes(chunk_, data);
  finishRecord(chunk_, at);

  if (message_count_ == 0) start_time_ = end_time_ = log_time;
  start_time_ = std::min(start_time_, log_time);
  end_time_ = std::max(end_time_, log_time);
  ++message_count_;
  ++channel_message_counts_[channel_id];
  if (chunk_.size() >= options_.chunk_bytes) flushChunk();
}

void McapWriter::flushChunk() {
  if (chunk_messages_.empty()) return;
  std::span<const std::uint8_t> stored = chunk_;
  if (zstd_) {
    compressed_.resize(ZSTD_compressBound(chunk_.size()));
    const std::size_t n = ZSTD_compressCCtx(static_cast<ZSTD_CCtx*>(zstd_), compressed_.data(), compressed_.size(),
                                            chunk_.data(), chunk_.size(), options_.zstd_level);
    if (ZSTD_isError(n)) throw std::runtime_error(path_.string() + ": zstd: " + ZSTD_getErrorName(n));
    stored = std::span<const std::uint8_t>(compressed_).first(n);
  }
  ChunkIndex index{chunk_start_, chunk_end_, offset_, 0, {}, 0, stored.size(), chunk_.size()};
  Bytes r;
  const auto at = beginRecord(r, Opcode::kChunk);
  put(r, chunk_start_);
  put(r, chunk_end_);
  put(r, std::uint64_t(chunk_.size()));
  put(r, crc32Update(0, chunk_));
  putString(r, options_.compression);
  put(r, std::uint64_t(stored.size()));
  putBytes(r, stored);
  finishRecord(r, at);
  index.length = r.size();
  emit(r, true);

  // Message indexes, one per channel of the chunk, right after it.
  Bytes indexes;
  for (const auto& [channel, entries] : chunk_messages_) {
    index.message_index_offsets[channel] = offset_ + indexes.size();
    const auto mi = beginRecord(indexes, Opcode::kMessageIndex);
    put(indexes, channel);
    put(indexes, std::uint32_t(entries.size() * 16));
    for (const auto& [time, offset] : entries) {
      put(indexes, time);
      put(indexes, offset);
    }
    finishRecord(indexes, mi);
  }
  index.message_index_length = indexes.size();
  emit(indexes, true);
  chunk_indexes_.push_back(std::move(index));
  chunk_.clear();
  chunk_messages_.clear();
}

void McapWriter::close() {
  if (closed_) return;
  flushChunk();
  Bytes end;
  const auto at = beginRecord(end, Opcode::kDataEnd);
  put(end, data_crc_);
  finishRecord(end, at);
  emit(end, false);

  // Summary: groups of schemas, channels, statistics, chunk indexes; then offsets to each group.
  const std::uint64_t summary_start = offset_;
  Bytes summary;
  struct Group {
    Opcode opcode;
    std::uint64_t start, length;
  };
  std::vector<Group> groups;
  auto group = [&](Opcode opcode, const Bytes& records) {
    if (records.empty()) return;
    groups.push_back({opcode, summary_start + summary.size(), records.size()});
    putBytes(summary, records);
  };
  group(Opcode::kSchema, schemas_);
  group(Opcode::kChannel, channels_);
  Bytes stats;
  const auto s = beginRecord(stats, Opcode::kStatistics);
  put(stats, message_count_);
  put(stats, schema_count_);
  put(stats, std::uint32_t(channel_count_));
  put(stats, std::uint32_t(0));  // attachments
  put(stats, std::uint32_t(0));  // metadata
  put(stats, std::uint32_t(chunk_indexes_.size()));
  put(stats, start_time_);
  put(stats, end_time_);
  putIdMap(stats, channel_message_counts_);
  finishRecord(stats, s);
  group(Opcode::kStatistics, stats);
  Bytes chunk_index_records;
  for (const auto& c : chunk_indexes_) {
    const auto ci = beginRecord(chunk_index_records, Opcode::kChunkIndex);
    put(chunk_index_records, c.start_time);
    put(chunk_index_records, c.end_time);
    put(chunk_index_records, c.offset);
    put(chunk_index_records, c.length);
    putIdMap(chunk_index_records, c.message_index_offsets);
    put(chunk_index_records, c.message_index_length);
    putString(chunk_index_records, options_.compression);
    put(chunk_index_records, c.compressed_size);
    put(chunk_index_records, c.uncompressed_size);
    finishRecord(chunk_index_records, ci);
  }
  group(Opcode::kChunkIndex, chunk_index_records);
  const std::uint64_t summary_offset_start = summary_start + summary.size();
  for (const auto& g : groups) {
    const auto so = beginRecord(summary, Opcode::kSummaryOffset);
    put(summary, std::uint8_t(g.opcode));
    put(summary, g.start);
    put(summary, g.length);
    finishRecord(summary, so);
  }

  Bytes tail;
  put(tail, std::uint8_t(Opcode::kFooter));
  put(tail, std::uint64_t(mcap::kFooterBodySize));  // known now: the CRC below covers it
  put(tail, options_.summary ? summary_start : std::uint64_t(0));
  put(tail, options_.summary ? summary_offset_start : std::uint64_t(0));
  // Covers the summary, its offsets and the footer up to this field.
  std::uint32_t crc = 0;
  if (options_.summary) crc = crc32Update(crc32Update(0, summary), tail);
  put(tail, crc);
  tail.insert(tail.end(), mcap::kMagic.begin(), mcap::kMagic.end());
  if (options_.summary) emit(summary, false);
  emit(tail, false);
  file_->commit();
  closed_ = true;
}

}  // namespace rigcal::bag
