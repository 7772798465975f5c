#pragma once
// One storage file of a bag (an .mcap or a .db3), read as a stream of messages in log-time order.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <span>
#include <string>
#include <vector>

#include "rigcal/core/time.hpp"

namespace rigcal::bag {

struct TopicInfo {
  std::string name;
  std::string type;                  // e.g. "sensor_msgs/msg/PointCloud2"
  std::string serialization_format;  // "cdr" for ROS 2
};

struct StoredMessage {
  std::size_t topic = 0;  // index into the reader's topics()
  TimeNs log_time_ns = 0;
  std::span<const std::uint8_t> data;  // valid until the reader's next call
};

class StorageReader {
 public:
  virtual ~StorageReader() = default;
  /// Every topic the file declares (it may grow while reading a file without a summary).
  [[nodiscard]] virtual const std::vector<TopicInfo>& topics() const = 0;
  /// The next message by log time, nullopt at the end. Throws BagError on corrupt content.
  virtual std::optional<StoredMessage> next() = 0;
  /// Non-empty when the file ended early (truncated): what was read before the cut is still delivered.
  [[nodiscard]] virtual std::string warning() const { return {}; }
  [[nodiscard]] virtual const std::filesystem::path& path() const = 0;
};

}  // namespace rigcal::bag
