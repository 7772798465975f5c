#pragma once
// A ROS 2 bag: a rosbag2 folder (metadata.yaml naming one or several split files), a folder of storage
// files, or a single .mcap / .db3 file. Messages of every file and topic come out merged in log-time
// order, streamed: only each file's current chunk/row is in memory.
#include <cstdint>
#include <filesystem>
#include <memory>
#include <optional>
#include <queue>
#include <string>
#include <vector>

#include "rigcal/bag/storage_reader.hpp"

namespace rigcal::bag {

struct BagMessage {
  std::size_t topic = 0;  // index into Bag::topics()
  TimeNs log_time_ns = 0;
  std::span<const std::uint8_t> data;  // valid until the next call to Bag::next()
};

/// Opens one storage file, choosing MCAP or sqlite3 by its first bytes.
std::unique_ptr<StorageReader> openStorageFile(const std::filesystem::path& file);

class Bag {
 public:
  /// Throws BagError "<path>: <reason>" (no storage files, unreadable metadata, a corrupt file).
  explicit Bag(const std::filesystem::path& path);
  ~Bag();
  Bag(const Bag&) = delete;
  Bag& operator=(const Bag&) = delete;

  /// Topics of every file, by name (a topic split across files is one entry).
  [[nodiscard]] const std::vector<TopicInfo>& topics() const { return topics_; }
  [[nodiscard]] std::optional<std::size_t> findTopic(const std::string& name) const;
  /// "a, b, c": for errors that must list what the bag holds.
  [[nodiscard]] std::string topicList() const;
  [[nodiscard]] const std::vector<std::filesystem::path>& files() const { return files_; }
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }

  /// The next message of any file by log time (ties: earlier file first), nullopt at the end.
  std::optional<BagMessage> next();
  /// One line per file that ended early (truncated MCAP): its messages before the cut were delivered.
  [[nodiscard]] std::vector<std::string> warnings() const;

 private:
  std::size_t globalTopic(std::size_t file, std::size_t local);
  void advance(std::size_t file);

  struct Head {
    TimeNs log_time_ns;
    std::size_t file;
    bool operator>(const Head& o) const {
      return log_time_ns != o.log_time_ns ? log_time_ns > o.log_time_ns : file > o.file;
    }
  };

  std::filesystem::path path_;
  std::vector<std::filesystem::path> files_;
  std::vector<std::unique_ptr<StorageReader>> readers_;
  std::vector<std::optional<StoredMessage>> current_;
  std::vector<std::vector<std::size_t>> topic_map_;  // [file][local topic] -> global topic
  std::vector<TopicInfo> topics_;
  std::priority_queue<Head, std::vector<Head>, std::greater<>> heads_;
  std::optional<std::size_t> last_file_;
};

/// The one-line warning of a source streaming a bag topic (packets or clouds): the stream's own error (a cut
/// or corrupt chunk met while reading), the bag's warnings, and how many messages were malformed, the last named.
std::string bagSourceWarning(const std::string& stream_error, const Bag& bag, std::uint64_t malformed,
                             const std::string& last_malformed);

}  // namespace rigcal::bag
