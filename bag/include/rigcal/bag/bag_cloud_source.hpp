#pragma once
// The scans of a bag's sensor_msgs/PointCloud2 topic, in log-time order: each cloud is one Scan with
// per-point times (decodePointCloud2), bypassing packet decoding. A malformed message is counted and
// dropped; a corrupt chunk met while streaming ends the input with what was read (warning()).
#include <filesystem>
#include <optional>
#include <string>

#include "rigcal/bag/bag.hpp"
#include "rigcal/core/scan.hpp"
#include "rigcal/drivers/packet_source.hpp"

namespace rigcal::bag {

struct BagCloud {
  Scan scan;
  TimeNs log_time_ns = 0;  // when the cloud was recorded (its "arrival")
};

class BagCloudSource {
 public:
  /// Throws BagError as chooseLidarTopic, and when the topic is not a PointCloud2 topic.
  BagCloudSource(const std::filesystem::path& bag, const std::string& topic);

  std::optional<BagCloud> next();
  /// packets = clouds delivered, filtered = other topics' messages, malformed = clouds dropped.
  [[nodiscard]] const drivers::SourceStats& stats() const { return stats_; }
  [[nodiscard]] std::string warning() const;
  [[nodiscard]] const std::string& topic() const { return bag_.topics()[topic_].name; }

 private:
  Bag bag_;
  std::size_t topic_ = 0;
  drivers::SourceStats stats_;
  std::uint64_t sequence_ = 0;
  std::string stream_error_, last_malformed_;
};

}  // namespace rigcal::bag
