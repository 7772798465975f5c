#pragma once
// A streaming MCAP reader. With a summary (chunk indexes) it reads only the chunks it needs, in
// message-time order; without one (or when the file was cut short) it first walks the records once to
// find chunks and channels, checking CRCs, and keeps what came before a cut with a warning. Memory holds
// only the chunks whose time ranges overlap the message being delivered, and the next chunk, which a
// second thread reads and inflates (CRC checked) while the caller decodes the current one; its errors
// surface when the reader reaches that chunk, as they would without it.
#include <cstdint>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <queue>
#include <string>
#include <vector>

#include "rigcal/bag/chunk_decompressor.hpp"
#include "rigcal/bag/mcap_records.hpp"
#include "rigcal/bag/page_buffer.hpp"
#include "rigcal/bag/read_only_file.hpp"
#include "rigcal/bag/storage_reader.hpp"

namespace rigcal::bag {

class PrefetchThread;

class McapFile final : public StorageReader {
 public:
  /// Throws BagError "<file>: <reason>" (not MCAP, corrupt summary, bad data-section CRC, ...).
  explicit McapFile(const std::filesystem::path& path);
  ~McapFile() override;

  [[nodiscard]] const std::vector<TopicInfo>& topics() const override { return topics_; }
  std::optional<StoredMessage> next() override;
  [[nodiscard]] std::string warning() const override { return warning_; }
  [[nodiscard]] const std::filesystem::path& path() const override { return path_; }
  /// True when the summary's chunk index was used (false: linear scan).
  [[nodiscard]] bool indexed() const { return indexed_; }
  /// Chunks (or unchunked messages) found.
  [[nodiscard]] std::size_t chunkCount() const { return refs_.size(); }
  /// Most chunks held in memory at once so far: the streaming bound (1-2 unless chunk times overlap).
  [[nodiscard]] std::size_t peakLoadedChunks() const { return peak_loaded_; }

 private:
  // A chunk, or a lone message record outside any chunk, with the time range of what it holds.
  struct Ref {
    std::uint64_t start_time = 0, end_time = 0, offset = 0, length = 0;  // length: whole record
  };
  struct Entry {
    std::uint64_t log_time = 0;
    std::uint32_t offset = 0, length = 0;
    std::size_t topic = 0;
  };
  // Exhausted chunks go back to spare_ and their buffers are reused by the next load.
  struct Loaded {
    PageBuffer record, inflated;
    std::vector<Entry> entries;
    std::size_t next = 0;
    std::span<const std::uint8_t> records;
    std::size_t order = 0;  // ties between chunks go to the earlier one
    std::uint8_t opcode = 0;  // of the record: a chunk, or a lone message
  };
  struct HeapItem {
    std::uint64_t log_time;
    std::size_t order;
    Loaded* chunk;
    bool operator>(const HeapItem& o) const {
      return log_time != o.log_time ? log_time > o.log_time : order > o.order;
    }
  };

  bool readSummary();
  void scanLinearly();
  std::string where(std::uint64_t offset) const;
  void addSchema(const mcap::SchemaRecord& s);
  void addChannel(const mcap::ChannelRecord& c, const std::string& what);
  /// Walks a chunk's records: registers schemas/channels and lists its messages.
  void indexRecords(std::span<const std::uint8_t> records, const std::string& what, std::vector<Entry>* entries);
  std::unique_ptr<Loaded> spareChunk();
  /// Reads the record of `ref` into `chunk` and inflates a chunk (CRC checked). Touches only `chunk`, the
  /// file and `decompressor`: it runs on the prefetch thread too.
  void fetch(const Ref& ref, Loaded& chunk, mcap::ChunkDecompressor& decompressor) const;
  void load(const Ref& ref, std::size_t order);
  void prefetch(std::size_t order);

  std::filesystem::path path_;
  ReadOnlyFile file_;
  std::vector<TopicInfo> topics_;
  std::map<std::uint16_t, std::string> schema_names_;
  std::map<std::uint16_t, std::size_t> channel_topic_;
  std::vector<Ref> refs_;
  std::size_t next_ref_ = 0;
  bool indexed_ = false;
  std::string warning_;
  mcap::ChunkDecompressor decompressor_;
  std::vector<std::unique_ptr<Loaded>> loaded_, spare_;
  std::priority_queue<HeapItem, std::vector<HeapItem>, std::greater<>> heap_;
  Loaded* retired_ = nullptr;
  std::size_t peak_loaded_ = 0;  // exhausted chunk whose bytes the last message still points into
  // The next chunk, fetched on prefetch_ while the caller decodes the current ones.
  std::unique_ptr<Loaded> ahead_;
  std::size_t ahead_order_ = 0;
  mcap::ChunkDecompressor ahead_decompressor_;  // the prefetch thread's own zstd / lz4 contexts
  std::unique_ptr<PrefetchThread> prefetch_;    // last: joined before anything its job uses is destroyed
};

}  // namespace rigcal::bag
