#include "rigcal/bag/mcap_file.hpp"

#include <algorithm>
#include <array>
#include <cstring>

#include "rigcal/bag/bag_error.hpp"
#include "rigcal/bag/byte_cursor.hpp"
#include "rigcal/bag/crc32.hpp"
#include "prefetch_thread.hpp"

namespace rigcal::bag {

namespace {

using mcap::Opcode;

std::uint8_t op(Opcode o) { return std::uint8_t(o); }

struct RecordHeader {
  std::uint8_t opcode = 0;
  std::uint64_t length = 0;
};

RecordHeader parseHeader(std::span<const std::uint8_t, mcap::kRecordHeaderSize> bytes) {
  RecordHeader h;
  h.opcode = bytes[0];
  std::memcpy(&h.length, bytes.data() + 1, sizeof h.length);
  return h;
}

}  // namespace

McapFile::McapFile(const std::filesystem::path& path) : path_(path), file_(path) {
  std::array<std::uint8_t, 8> magic{};
  if (file_.readAt(0, magic) != magic.size() || magic != mcap::kMagic)
    throw BagError(path_.string() + ": not an MCAP file (no magic at offset 0)");
  if (!readSummary()) scanLinearly();
  std::stable_sort(refs_.begin(), refs_.end(), [](const Ref& a, const Ref& b) {
    return a.start_time != b.start_time ? a.start_time < b.start_time : a.offset < b.offset;
  });
}

McapFile::~McapFile() = default;

std::string McapFile::where(std::uint64_t offset) const {
  return path_.string() + ": record at offset " + std::to_string(offset);
}

void McapFile::addSchema(const mcap::SchemaRecord& s) { schema_names_[s.id] = s.name; }

void McapFile::addChannel(const mcap::ChannelRecord& c, const std::string& what) {
  if (channel_topic_.count(c.id)) return;
  std::string type;
  if (c.schema_id != 0) {
    const auto it = schema_names_.find(c.schema_id);
    if (it == schema_names_.end())
      throw BagError(what + ": channel " + std::to_string(c.id) + " (" + c.topic + ") names unknown schema " +
                     std::to_string(c.schema_id));
    type = it->second;
  }
  auto topic = std::find_if(topics_.begin(), topics_.end(), [&](const TopicInfo& t) { return t.name == c.topic; });
  if (topic == topics_.end()) {
    topics_.push_back({c.topic, type, c.message_encoding});
    topic = topics_.end() - 1;
  }
  channel_topic_[c.id] = std::size_t(topic - topics_.begin());
}

bool McapFile::readSummary() {
  constexpr std::uint64_t kFooterRecord = mcap::kRecordHeaderSize + mcap::kFooterBodySize;
  const std::uint64_t size = file_.size();
  if (size < 8 + kFooterRecord + 8) return false;
  const std::uint64_t footer_pos = size - 8 - kFooterRecord;
  std::array<std::uint8_t, kFooterRecord + 8> tail{};
  if (file_.readAt(footer_pos, tail) != tail.size()) return false;
  if (!std::equal(mcap::kMagic.begin(), mcap::kMagic.end(), tail.begin() + kFooterRecord)) return false;
  const auto header = parseHeader(std::span<const std::uint8_t, mcap::kRecordHeaderSize>(tail.data(), 9));
  if (header.opcode != op(Opcode::kFooter) || header.length != mcap::kFooterBodySize) return false;
  const auto footer =
      mcap::parseFooter(std::span(tail).subspan(mcap::kRecordHeaderSize, mcap::kFooterBodySize), where(footer_pos));
  if (footer.summary_start == 0) return false;
  if (footer.summary_start < 8 || footer.summary_start > footer_pos)
    throw BagError(where(footer_pos) + ": footer's summary start " + std::to_string(footer.summary_start) +
                   " lies outside the file");

  std::vector<std::uint8_t> summary(std::size_t(footer_pos - footer.summary_start));
  file_.readAt(footer.summary_start, summary);
  if (footer.summary_crc != 0) {
    // Covers the summary and summary-offset sections and the footer up to its CRC field.
    std::uint32_t crc = crc32Update(0, summary);
    crc = crc32Update(crc, std::span(tail).first(kFooterRecord - 4));
    if (crc != footer.summary_crc)
      throw BagError(where(footer_pos) + ": summary CRC mismatch (stored " + std::to_string(footer.summary_crc) +
                     ", computed " + std::to_string(crc) + ")");
  }
  std::vector<mcap::ChannelRecord> channels;
  std::vector<Ref> refs;
  mcap::RecordSplitter records(summary, path_.string() + ": summary at offset " + std::to_string(footer.summary_start));
  while (const auto r = records.next()) {
    const std::string what = where(footer.summary_start + r->offset);
    if (r->opcode == op(Opcode::kSchema)) {
      addSchema(mcap::parseSchema(r->body, what));
    } else if (r->opcode == op(Opcode::kChannel)) {
      channels.push_back(mcap::parseChannel(r->body, what));
    } else if (r->opcode == op(Opcode::kChunkIndex)) {
      const auto index = mcap::parseChunkIndex(r->body, what);
      if (index.chunk_start_offset < 8 || index.chunk_length > footer.summary_start ||
          index.chunk_start_offset > footer.summary_start - index.chunk_length)
        throw BagError(what + ": chunk index points outside the data section (offset " +
                       std::to_string(index.chunk_start_offset) + ", length " + std::to_string(index.chunk_length) +
                       ")");
      refs.push_back({index.message_start_time, index.message_end_time, index.chunk_start_offset, index.chunk_length});
    }
  }
  if (refs.empty()) return false;  // no chunk index: messages are found by walking the file
  for (const auto& c : channels) addChannel(c, where(footer.summary_start));
  refs_ = std::move(refs);
  indexed_ = true;
  return true;
}

void McapFile::indexRecords(std::span<const std::uint8_t> records, const std::string& what,
                            std::vector<Entry>* entries) {
  mcap::RecordSplitter split(records, what);
  while (const auto r = split.next()) {
    if (r->opcode == op(Opcode::kSchema)) {
      addSchema(mcap::parseSchema(r->body, what));
    } else if (r->opcode == op(Opcode::kChannel)) {
      addChannel(mcap::parseChannel(r->body, what), what);
    } else if (r->opcode == op(Opcode::kMessage)) {
      const auto m = mcap::parseMessage(r->body, what);
      const auto channel = channel_topic_.find(m.channel_id);
      if (channel == channel_topic_.end())
        throw BagError(what + ": message at byte " + std::to_string(r->offset) + " on unknown channel " +
                       std::to_string(m.channel_id));
      if (entries)
        entries->push_back({m.log_time, std::uint32_t(m.data.data() - records.data()), std::uint32_t(m.data.size()),
                            channel->second});
    }
  }
}

void McapFile::scanLinearly() {
  const std::uint64_t size = file_.size();
  std::uint64_t pos = 8;
  // Writers compute the data-section CRC from the file's first byte (magic and header included); a
  // reading of the spec that starts after the Header record is accepted too rather than refuse a good file.
  std::uint32_t data_crc = crc32Update(0, mcap::kMagic);
  std::uint32_t data_crc_after_header = 0;
  bool in_data = true, footer_seen = false;
  PageBuffer body_buffer, inflated;
  std::vector<Entry> entries;
  while (true) {
    std::array<std::uint8_t, mcap::kRecordHeaderSize> head{};
    if (size - pos < head.size()) {
      if (pos != size)
        warning_ = path_.string() + ": truncated at offset " + std::to_string(pos) + " inside a record header";
      break;
    }
    file_.readAt(pos, head);
    const auto h = parseHeader(head);
    if (h.length > size - pos - head.size()) {
      warning_ = path_.string() + ": truncated at offset " + std::to_string(pos) + ": record (opcode " +
                 std::to_string(h.opcode) + ") claims " + std::to_string(h.length) + " bytes, the file has " +
                 std::to_string(size - pos - head.size()) + " left";
      break;
    }
    if (h.opcode == op(Opcode::kFooter)) {
      footer_seen = true;
      break;
    }
    if (h.length > mcap::kMaxChunkBytes)
      throw BagError(where(pos) + ": record of " + std::to_string(h.length) + " bytes is larger than accepted");
    const auto body = body_buffer.resize(std::size_t(h.length));
    file_.readAt(pos + head.size(), body);
    const std::string what = where(pos);
    if (h.opcode == op(Opcode::kDataEnd)) {
      const std::uint32_t stored = mcap::parseDataEnd(body, what);
      if (in_data && stored != 0 && stored != data_crc && stored != data_crc_after_header)
        throw BagError(what + ": data section CRC mismatch (stored " + std::to_string(stored) + ", computed " +
                       std::to_string(data_crc) + ")");
      in_data = false;
    } else if (in_data) {
      data_crc = crc32Update(crc32Update(data_crc, head), body);
      if (h.opcode != op(Opcode::kHeader))
        data_crc_after_header = crc32Update(crc32Update(data_crc_after_header, head), body);
    }
    if (h.opcode == op(Opcode::kSchema)) {
      addSchema(mcap::parseSchema(body, what));
    } else if (h.opcode == op(Opcode::kChannel)) {
      addChannel(mcap::parseChannel(body, what), what);
    } else if (h.opcode == op(Opcode::kMessage)) {
      const auto m = mcap::parseMessage(body, what);
      if (!channel_topic_.count(m.channel_id))
        throw BagError(what + ": message on unknown channel " + std::to_string(m.channel_id));
      refs_.push_back({m.log_time, m.log_time, pos, head.size() + h.length});
    } else if (h.opcode == op(Opcode::kChunk)) {
      const std::string chunk_what = path_.string() + ": chunk at offset " + std::to_string(pos);
      const auto chunk = mcap::parseChunk(body, chunk_what);
      entries.clear();
      indexRecords(decompressor_.inflate(chunk, inflated, chunk_what), chunk_what, &entries);
      if (!entries.empty()) {
        const auto [lo, hi] = std::minmax_element(entries.begin(), entries.end(),
                                                  [](const Entry& a, const Entry& b) { return a.log_time < b.log_time; });
        refs_.push_back({lo->log_time, hi->log_time, pos, head.size() + h.length});
      }
    }
    pos += head.size() + h.length;
  }
  if (warning_.empty() && !footer_seen)
    warning_ = path_.string() + ": truncated at offset " + std::to_string(pos) + ": no footer";
  if (!warning_.empty())
    warning_ += " (using the " + std::to_string(refs_.size()) + " chunks before the cut)";
}

std::unique_ptr<McapFile::Loaded> McapFile::spareChunk() {
  if (spare_.empty()) return std::make_unique<Loaded>();
  std::unique_ptr<Loaded> chunk = std::move(spare_.back());
  spare_.pop_back();
  chunk->entries.clear();
  chunk->next = 0;
  return chunk;
}

void McapFile::fetch(const Ref& ref, Loaded& chunk, mcap::ChunkDecompressor& decompressor) const {
  const std::string what = path_.string() + ": chunk at offset " + std::to_string(ref.offset);
  const auto record = chunk.record.resize(std::size_t(ref.length));
  if (ref.length < mcap::kRecordHeaderSize || file_.readAt(ref.offset, record) != ref.length)
    throw BagError(what + ": record of " + std::to_string(ref.length) + " bytes cut short by the end of the file");
  const auto h = parseHeader(std::span<const std::uint8_t, mcap::kRecordHeaderSize>(record.data(), 9));
  const auto body = std::span<const std::uint8_t>(record).subspan(mcap::kRecordHeaderSize);
  if (h.length != body.size())
    throw BagError(what + ": record length " + std::to_string(h.length) + " disagrees with the index (" +
                   std::to_string(body.size()) + ")");
  chunk.opcode = h.opcode;
  if (h.opcode == op(Opcode::kChunk)) chunk.records = decompressor.inflate(mcap::parseChunk(body, what), chunk.inflated, what);
  else if (h.opcode == op(Opcode::kMessage)) chunk.records = body;
  else throw BagError(what + ": expected a chunk, found opcode " + std::to_string(h.opcode));
}

void McapFile::prefetch(std::size_t order) {
  if (ahead_ || order >= refs_.size()) return;
  if (!prefetch_) prefetch_ = std::make_unique<PrefetchThread>();
  ahead_ = spareChunk();
  ahead_order_ = order;
  prefetch_->submit([this, ref = refs_[order], chunk = ahead_.get()] { fetch(ref, *chunk, ahead_decompressor_); });
}

void McapFile::load(const Ref& ref, std::size_t order) {
  std::unique_ptr<Loaded> chunk;
  if (ahead_ && ahead_order_ == order) {
    std::unique_ptr<Loaded> fetched = std::move(ahead_);
    prefetch_->wait();  // rethrows the chunk's error, here where the reader reaches it
    chunk = std::move(fetched);
  } else {
    if (ahead_) {  // not the chunk asked for (not expected: chunks load in order): let it finish, keep its buffers
      try {
        prefetch_->wait();
      } catch (const std::exception&) {  // that chunk's error belongs to when it is loaded
      }
      spare_.push_back(std::move(ahead_));
    }
    chunk = spareChunk();
    fetch(ref, *chunk, decompressor_);
  }
  chunk->order = order;
  if (chunk->opcode == op(Opcode::kChunk)) {
    const std::string what = path_.string() + ": chunk at offset " + std::to_string(ref.offset);
    indexRecords(chunk->records, what, &chunk->entries);
    std::stable_sort(chunk->entries.begin(), chunk->entries.end(),
                     [](const Entry& a, const Entry& b) { return a.log_time < b.log_time; });
  } else {
    const auto m = mcap::parseMessage(chunk->records, where(ref.offset));
    chunk->entries.push_back({m.log_time, std::uint32_t(m.data.data() - chunk->records.data()),
                              std::uint32_t(m.data.size()), channel_topic_.at(m.channel_id)});
  }
  // The next chunk is read and inflated while the caller decodes this one's messages.
  prefetch(order + 1);
  if (chunk->entries.empty()) {
    spare_.push_back(std::move(chunk));
    return;
  }
  heap_.push({chunk->entries.front().log_time, order, chunk.get()});
  loaded_.push_back(std::move(chunk));
  peak_loaded_ = std::max(peak_loaded_, loaded_.size());
}

std::optional<StoredMessage> McapFile::next() {
  if (retired_) {
    const auto it =
        std::find_if(loaded_.begin(), loaded_.end(), [&](const std::unique_ptr<Loaded>& c) { return c.get() == retired_; });
    spare_.push_back(std::move(*it));
    loaded_.erase(it);
    retired_ = nullptr;
  }
  while (next_ref_ < refs_.size() && (heap_.empty() || refs_[next_ref_].start_time <= heap_.top().log_time)) {
    load(refs_[next_ref_], next_ref_);
    ++next_ref_;
  }
  if (heap_.empty()) return std::nullopt;
  const HeapItem top = heap_.top();
  heap_.pop();
  Loaded& chunk = *top.chunk;
  const Entry& e = chunk.entries[chunk.next++];
  if (chunk.next < chunk.entries.size())
    heap_.push({chunk.entries[chunk.next].log_time, chunk.order, &chunk});
  else
    retired_ = &chunk;
  return StoredMessage{e.topic, TimeNs(e.log_time), chunk.records.subspan(e.offset, e.length)};
}

}  // namespace rigcal::bag
