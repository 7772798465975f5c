#pragma once
// Which topic of a bag a lidar's data comes from, and in which form: raw packets (into our decoders) or
// sensor_msgs/PointCloud2 (scans straight into the pipeline). One rule for every command that reads a bag.
#include <string>

#include "rigcal/bag/bag.hpp"

namespace rigcal::bag {

enum class LidarTopicForm { kPackets, kPointCloud2 };

struct LidarTopic {
  std::size_t index = 0;  // into Bag::topics()
  std::string name, type;
  LidarTopicForm form = LidarTopicForm::kPackets;
};

/// `topic` empty: the bag's only packet or PointCloud2 topic. Throws BagError "<bag>: ..." when the bag is
/// empty, the topic is not in it (listing the bag's topics), its type is neither a packet type nor
/// PointCloud2 (naming the accepted types), or the choice is ambiguous (naming the candidates).
LidarTopic chooseLidarTopic(const Bag& bag, const std::string& topic);

/// The header frame_id of the topic's first message (its sensor's tf frame), reading `bag` from where it
/// is; empty when the topic has no message, its type has no header (ouster PacketMsg) or the id is empty.
std::string firstFrameId(Bag& bag, const LidarTopic& topic);

}  // namespace rigcal::bag
