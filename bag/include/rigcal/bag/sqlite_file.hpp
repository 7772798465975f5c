#pragma once
// A rosbag2 sqlite3 storage file (.db3): tables topics(id, name, type, serialization_format, ...) and
// messages(id, topic_id, timestamp, data), streamed by timestamp through one sqlite statement.
#include <cstdint>
#include <filesystem>
#include <map>
#include <string>
#include <vector>

#include "rigcal/bag/storage_reader.hpp"

struct sqlite3;
struct sqlite3_stmt;

namespace rigcal::bag {

class SqliteFile final : public StorageReader {
 public:
  /// Opens read-only (immutable: no journal or lock files, so read-only folders work).
  /// Throws BagError "<file>: sqlite: <reason>".
  explicit SqliteFile(const std::filesystem::path& path);
  ~SqliteFile() override;
  SqliteFile(const SqliteFile&) = delete;
  SqliteFile& operator=(const SqliteFile&) = delete;

  [[nodiscard]] const std::vector<TopicInfo>& topics() const override { return topics_; }
  std::optional<StoredMessage> next() override;
  [[nodiscard]] const std::filesystem::path& path() const override { return path_; }

 private:
  [[noreturn]] void fail(const std::string& doing) const;

  std::filesystem::path path_;
  sqlite3* db_ = nullptr;
  sqlite3_stmt* messages_ = nullptr;
  std::vector<TopicInfo> topics_;
  std::map<std::int64_t, std::size_t> topic_of_id_;
};

}  // namespace rigcal::bag
