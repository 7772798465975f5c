#pragma once
// Writes a rosbag2 sqlite3 storage file (.db3: tables topics and messages, as rosbag2's sqlite3 plugin
// lays them out) for tests that need bags of our own: simulator recordings as packets or PointCloud2,
// /tf_static, Odometry. Written with libsqlite3, read back by the production reader.
#include <sqlite3.h>

#include <cstdint>
#include <filesystem>
#include <stdexcept>
#include <string>
#include <vector>

namespace rigcal::bag::test {

class SqliteBagWriter {
 public:
  explicit SqliteBagWriter(const std::filesystem::path& file) {
    std::filesystem::remove(file);
    if (sqlite3_open(file.c_str(), &db_) != SQLITE_OK) throw std::runtime_error("cannot create " + file.string());
    exec("CREATE TABLE topics(id INTEGER PRIMARY KEY, name TEXT NOT NULL, type TEXT NOT NULL, "
         "serialization_format TEXT NOT NULL, offered_qos_profiles TEXT NOT NULL)");
    exec("CREATE TABLE messages(id INTEGER PRIMARY KEY, topic_id INTEGER NOT NULL, timestamp INTEGER NOT NULL, "
         "data BLOB NOT NULL)");
    exec("BEGIN");
    if (sqlite3_prepare_v2(db_, "INSERT INTO messages(topic_id, timestamp, data) VALUES(?, ?, ?)", -1, &insert_,
                           nullptr) != SQLITE_OK)
      throw std::runtime_error("prepare");
  }
  ~SqliteBagWriter() {
    sqlite3_finalize(insert_);
    exec("COMMIT");
    sqlite3_close(db_);
  }
  SqliteBagWriter(const SqliteBagWriter&) = delete;
  SqliteBagWriter& operator=(const SqliteBagWriter&) = delete;

  /// Declares a topic; returns its id for write().
  int topic(const std::string& name, const std::string& type) {
    const int id = ++topics_;
    exec("INSERT INTO topics VALUES(" + std::to_string(id) + ", '" + name + "', '" + type + "', 'cdr', '')");
    return id;
  }
  void write(int topic, std::int64_t log_time_ns, const std::vector<std::uint8_t>& data) {
    sqlite3_reset(insert_);
    sqlite3_bind_int(insert_, 1, topic);
    sqlite3_bind_int64(insert_, 2, log_time_ns);
    sqlite3_bind_blob(insert_, 3, data.data(), int(data.size()), SQLITE_TRANSIENT);
    if (sqlite3_step(insert_) != SQLITE_DONE) throw std::runtime_error("insert");
  }

 private:
  void exec(const std::string& sql) {
    if (sqlite3_exec(db_, sql.c_str(), nullptr, nullptr, nullptr) != SQLITE_OK)
      throw std::runtime_error(sql + ": " + sqlite3_errmsg(db_));
  }
  sqlite3* db_ = nullptr;
  sqlite3_stmt* insert_ = nullptr;
  int topics_ = 0;
};

}  // namespace rigcal::bag::test
