#include "rigcal/bag/bag_packet_source.hpp"

#include "rigcal/bag/bag_error.hpp"

namespace rigcal::bag {

namespace {

// The vendors' default UDP ports: decoders ignore them, but replay and filters see familiar values.
std::uint16_t defaultPort(PacketMessageType type, bool difop) {
  switch (type) {
    case PacketMessageType::kRobosenseScan: return difop ? 7788 : 6699;
    case PacketMessageType::kOusterPacket: return 7502;
    default: return 2368;
  }
}

}  // namespace

BagPacketSource::BagPacketSource(const std::filesystem::path& bag, const std::string& topic) : bag_(bag) {
  if (bag_.topics().empty()) throw BagError(bag.string() + ": empty bag (no topics)");  // as lidar_topic.cpp says it
  if (topic.empty()) {
    std::vector<std::size_t> candidates;
    for (std::size_t i = 0; i < bag_.topics().size(); ++i)
      if (packetMessageType(bag_.topics()[i].type)) candidates.push_back(i);
    if (candidates.empty())
      throw BagError(bag.string() + ": no packet topic (" + packetMessageTypeList() + ") among " + bag_.topicList());
    if (candidates.size() > 1) {
      std::string names;
      for (std::size_t i : candidates) names += (names.empty() ? "" : ", ") + bag_.topics()[i].name;
      throw BagError(bag.string() + ": several packet topics (" + names + "): choose one with --topic");
    }
    topic_ = candidates.front();
  } else {
    const auto found = bag_.findTopic(topic);
    if (!found) throw BagError(bag.string() + ": topic " + topic + " not in the bag; it has " + bag_.topicList());
    topic_ = *found;
  }
  const auto type = packetMessageType(bag_.topics()[topic_].type);
  if (!type)
    throw BagError(bag.string() + ": topic " + bag_.topics()[topic_].name + " has type " + bag_.topics()[topic_].type +
                   ", not a packet type (" + packetMessageTypeList() + ")");
  message_type_ = *type;
}

std::optional<drivers::UdpPacket> BagPacketSource::next() {
  while (next_packet_ >= pending_.size()) {
    pending_.clear();
    next_packet_ = 0;
    if (!stream_error_.empty()) return std::nullopt;
    std::optional<BagMessage> message;
    try {
      message = bag_.next();
    } catch (const BagError& e) {
      stream_error_ = e.what();  // keep what was decoded so far; the caller reports the cut
      return std::nullopt;
    }
    if (!message) return std::nullopt;
    if (message->topic != topic_) {
      ++stats_.filtered;
      continue;
    }
    ++messages_;
    try {
      decodePacketMessage(message_type_, message->data, message->log_time_ns,
                          bag_.path().string() + ": " + topic() + " message at log time " +
                              std::to_string(message->log_time_ns),
                          pending_);
    } catch (const BagError& e) {
      pending_.clear();
      ++stats_.malformed;
      last_malformed_ = e.what();
    }
  }
  const ScanPacket& p = pending_[next_packet_++];
  ++stats_.packets;
  drivers::UdpPacket out;
  out.payload = p.data;
  out.receive_ns = p.stamp_ns;
  out.destination.port = defaultPort(message_type_, p.is_difop);
  return out;
}

std::string BagPacketSource::warning() const {
  return bagSourceWarning(stream_error_, bag_, stats_.malformed, last_malformed_);
}

}  // namespace rigcal::bag
