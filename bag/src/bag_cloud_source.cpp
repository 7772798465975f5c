#include "rigcal/bag/bag_cloud_source.hpp"

#include "rigcal/bag/bag_error.hpp"
#include "rigcal/bag/lidar_topic.hpp"
#include "rigcal/bag/point_cloud2_message.hpp"

namespace rigcal::bag {

BagCloudSource::BagCloudSource(const std::filesystem::path& bag, const std::string& topic) : bag_(bag) {
  const LidarTopic chosen = chooseLidarTopic(bag_, topic);
  if (chosen.form != LidarTopicForm::kPointCloud2)
    throw BagError(bag.string() + ": topic " + chosen.name + " has type " + chosen.type + ", not " + kPointCloud2Type);
  topic_ = chosen.index;
}

std::optional<BagCloud> BagCloudSource::next() {
  while (stream_error_.empty()) {
    std::optional<BagMessage> message;
    try {
      message = bag_.next();
    } catch (const BagError& e) {
      stream_error_ = e.what();  // what was delivered before the damage stays delivered
      return std::nullopt;
    }
    if (!message) return std::nullopt;
    if (message->topic != topic_) {
      ++stats_.filtered;
      continue;
    }
    try {
      DecodedCloud cloud = decodePointCloud2(message->data, bag_.path().string() + ": " + topic() +
                                                                " message at log time " +
                                                                std::to_string(message->log_time_ns));
      if (cloud.scan.empty()) continue;  // every point NaN: nothing to map or calibrate
      cloud.scan.sequence = sequence_++;
      ++stats_.packets;
      return BagCloud{std::move(cloud.scan), message->log_time_ns};
    } catch (const BagError& e) {
      ++stats_.malformed;
      last_malformed_ = e.what();
    }
  }
  return std::nullopt;
}

std::string BagCloudSource::warning() const {
  return bagSourceWarning(stream_error_, bag_, stats_.malformed, last_malformed_);
}

}  // namespace rigcal::bag
