#pragma once
// What a ROS 2 bag holds, read in one streaming pass: each topic's type, message count, rate and frame
// id, the tf edges (with their transforms) and, for lidar topics, a model guess from the first packet or
// cloud. Shared by `rigcal inspect` (which prints it) and `rigcal rig-from-bag` (which writes a rig).
#include <map>
#include <string>
#include <vector>

#include "rigcal/bag/lidar_model_guess.hpp"
#include "rigcal/bag/storage_reader.hpp"
#include "rigcal/bag/tf_message.hpp"

namespace rigcal::app {

struct BagTopicSummary {
  bag::TopicInfo info;
  std::uint64_t count = 0, bytes = 0;
  TimeNs first = 0, last = 0;
  std::string frame_id;
  bool frame_read = false;
  bool lidar = false;            // a packet-scan or PointCloud2 topic
  bag::ModelGuess model;         // lidar topics: from the first packet / cloud
  std::size_t cloud_points = 0;  // PointCloud2: points of the first cloud
  [[nodiscard]] double rateHz() const;
};

struct BagSummary {
  std::string path;
  std::size_t files = 0;
  std::vector<BagTopicSummary> topics;
  std::uint64_t total = 0, malformed = 0;
  std::string last_malformed;
  std::vector<std::string> warnings;
  // tf edges (parent, child) -> the first transform seen and its topic.
  std::map<std::pair<std::string, std::string>, std::pair<bag::StampedTransform, std::string>> tf;
};

/// Throws bag::BagError when the bag cannot be read.
BagSummary summarizeBag(const std::string& path);

/// The listing `rigcal inspect` prints (stdout), warnings on stderr.
void printBagSummary(const BagSummary& summary);

}  // namespace rigcal::app
