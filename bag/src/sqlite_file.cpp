#include "rigcal/bag/sqlite_file.hpp"

#include <sqlite3.h>

#include "rigcal/bag/bag_error.hpp"

namespace rigcal::bag {

namespace {

// An sqlite URI for the path: '%', '?' and '#' would otherwise be read as URI syntax.
std::string fileUri(const std::filesystem::path& path) {
  std::string uri = "file:";
  for (const char c : std::filesystem::absolute(path).string()) {
    if (c == '%' || c == '?' || c == '#') {
      static constexpr char kHex[] = "0123456789ABCDEF";
      uri += '%';
      uri += kHex[(unsigned char)c >> 4];
      uri += kHex[(unsigned char)c & 15];
    } else {
      uri += c;
    }
  }
  return uri + "?immutable=1";
}

std::string columnText(sqlite3_stmt* s, int column) {
  const auto* text = sqlite3_column_text(s, column);
  return text ? reinterpret_cast<const char*>(text) : "";
}

}  // namespace

void SqliteFile::fail(const std::string& doing) const {
  throw BagError(path_.string() + ": sqlite: " + doing + ": " + (db_ ? sqlite3_errmsg(db_) : "out of memory"));
}

SqliteFile::SqliteFile(const std::filesystem::path& path) : path_(path) {
  if (!std::filesystem::is_regular_file(path)) throw BagError(path.string() + ": sqlite: no such file");
  if (sqlite3_open_v2(fileUri(path).c_str(), &db_, SQLITE_OPEN_READONLY | SQLITE_OPEN_URI, nullptr) != SQLITE_OK) {
    const std::string reason = db_ ? sqlite3_errmsg(db_) : "out of memory";
    sqlite3_close(db_);
    throw BagError(path.string() + ": sqlite: cannot open: " + reason);
  }
  try {
    sqlite3_stmt* s = nullptr;
    if (sqlite3_prepare_v2(db_, "SELECT id, name, type, serialization_format FROM topics", -1, &s, nullptr) != SQLITE_OK)
      fail("reading the topics table");
    int rc;
    while ((rc = sqlite3_step(s)) == SQLITE_ROW) {
      topic_of_id_[sqlite3_column_int64(s, 0)] = topics_.size();
      topics_.push_back({columnText(s, 1), columnText(s, 2), columnText(s, 3)});
    }
    sqlite3_finalize(s);
    if (rc != SQLITE_DONE) fail("reading the topics table");
    if (sqlite3_prepare_v2(db_, "SELECT topic_id, timestamp, data FROM messages ORDER BY timestamp, id", -1,
                           &messages_, nullptr) != SQLITE_OK)
      fail("reading the messages table");
  } catch (...) {
    sqlite3_finalize(messages_);
    sqlite3_close(db_);
    throw;
  }
}

SqliteFile::~SqliteFile() {
  sqlite3_finalize(messages_);
  sqlite3_close(db_);
}

std::optional<StoredMessage> SqliteFile::next() {
  const int rc = sqlite3_step(messages_);
  if (rc == SQLITE_DONE) return std::nullopt;
  if (rc != SQLITE_ROW) fail("reading a message");
  const std::int64_t topic_id = sqlite3_column_int64(messages_, 0);
  const auto topic = topic_of_id_.find(topic_id);
  if (topic == topic_of_id_.end())
    throw BagError(path_.string() + ": sqlite: message at timestamp " +
                   std::to_string(sqlite3_column_int64(messages_, 1)) + " names unknown topic id " +
                   std::to_string(topic_id));
  const auto* data = static_cast<const std::uint8_t*>(sqlite3_column_blob(messages_, 2));
  const auto size = std::size_t(sqlite3_column_bytes(messages_, 2));
  return StoredMessage{topic->second, sqlite3_column_int64(messages_, 1), {data, data ? size : 0}};
}

}  // namespace rigcal::bag
