#include "rigcal/bag/lidar_topic.hpp"

#include "rigcal/bag/bag_error.hpp"
#include "rigcal/bag/cdr_reader.hpp"
#include "rigcal/bag/packet_scan_message.hpp"
#include "rigcal/bag/point_cloud2_message.hpp"

namespace rigcal::bag {

namespace {
std::optional<LidarTopicForm> formOf(const std::string& type) {
  if (packetMessageType(type)) return LidarTopicForm::kPackets;
  if (type == kPointCloud2Type) return LidarTopicForm::kPointCloud2;
  return std::nullopt;
}
}  // namespace

LidarTopic chooseLidarTopic(const Bag& bag, const std::string& topic) {
  const std::string where = bag.path().string() + ": ";
  if (bag.topics().empty()) throw BagError(where + "empty bag (no topics)");
  std::size_t index = 0;
  if (topic.empty()) {
    std::vector<std::size_t> candidates;
    for (std::size_t i = 0; i < bag.topics().size(); ++i)
      if (formOf(bag.topics()[i].type)) candidates.push_back(i);
    if (candidates.empty())
      throw BagError(where + "no lidar topic (" + packetMessageTypeList() + ", " + kPointCloud2Type + ") among " +
                     bag.topicList());
    if (candidates.size() > 1) {
      std::string names;
      for (std::size_t i : candidates) names += (names.empty() ? "" : ", ") + bag.topics()[i].name;
      throw BagError(where + "several lidar topics (" + names + "): name one (--topic, or the sensor's source.topic)");
    }
    index = candidates.front();
  } else {
    const auto found = bag.findTopic(topic);
    if (!found) throw BagError(where + "topic " + topic + " not in the bag; it has " + bag.topicList());
    index = *found;
  }
  const TopicInfo& info = bag.topics()[index];
  const auto form = formOf(info.type);
  if (!form)
    throw BagError(where + "topic " + info.name + " has type " + info.type + ", not a lidar type (" +
                   packetMessageTypeList() + ", " + kPointCloud2Type + ")");
  return {index, info.name, info.type, *form};
}

std::string firstFrameId(Bag& bag, const LidarTopic& topic) {
  if (packetMessageType(topic.type) == PacketMessageType::kOusterPacket) return {};
  while (const auto m = bag.next()) {
    if (m->topic != topic.index) continue;
    try {
      CdrReader cdr(m->data, bag.path().string() + ": " + topic.name);
      return cdr.readHeader().frame_id;
    } catch (const BagError&) {
      return {};
    }
  }
  return {};
}

}  // namespace rigcal::bag
