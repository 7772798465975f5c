#include "bag_summary.hpp"

#include <algorithm>
#include <cstdio>
#include <iomanip>
#include <iostream>

#include "rigcal/bag/bag.hpp"
#include "rigcal/bag/bag_error.hpp"
#include "rigcal/bag/cdr_reader.hpp"
#include "rigcal/bag/packet_scan_message.hpp"
#include "rigcal/bag/point_cloud2_message.hpp"

namespace rigcal::app {

namespace {

// Types whose first field is a std_msgs/Header (so the frame id can be read without their full layout).
bool startsWithHeader(const std::string& type) {
  static const char* const kPrefixes[] = {"sensor_msgs/msg/", "nav_msgs/msg/Odometry", "nav_msgs/msg/Path",
                                          "geometry_msgs/msg/PoseStamped", "geometry_msgs/msg/TransformStamped",
                                          "geometry_msgs/msg/PoseWithCovarianceStamped",
                                          "geometry_msgs/msg/TwistStamped"};
  if (bag::packetMessageType(type))
    return *bag::packetMessageType(type) != bag::PacketMessageType::kOusterPacket;
  return std::any_of(std::begin(kPrefixes), std::end(kPrefixes),
                     [&](const char* p) { return type.rfind(p, 0) == 0; });
}

// The first packet that is not RoboSense device info decides the model.
void guessFromPackets(BagTopicSummary& t, bag::PacketMessageType type, std::span<const std::uint8_t> data,
                      TimeNs log_time, const std::string& what) {
  std::vector<bag::ScanPacket> packets;
  bag::decodePacketMessage(type, data, log_time, what, packets);
  for (const auto& p : packets) {
    if (p.is_difop) continue;
    t.model = bag::guessModelFromPacket(type, p.data);
    t.frame_read = t.frame_read || type == bag::PacketMessageType::kOusterPacket;
    return;
  }
}

}  // namespace

double BagTopicSummary::rateHz() const {
  return count > 1 && last > first ? double(count - 1) / toSeconds(last - first) : 0.0;
}

BagSummary summarizeBag(const std::string& path) {
  BagSummary out;
  out.path = path;
  bag::Bag bag(path);
  std::vector<bool> model_read;
  while (const auto m = bag.next()) {
    while (out.topics.size() < bag.topics().size()) {
      BagTopicSummary t;
      t.info = bag.topics()[out.topics.size()];
      t.lidar = bag::packetMessageType(t.info.type) || t.info.type == bag::kPointCloud2Type;
      out.topics.push_back(t);
      model_read.push_back(!t.lidar);
    }
    BagTopicSummary& s = out.topics[m->topic];
    if (s.count == 0) s.first = m->log_time_ns;
    s.last = m->log_time_ns;
    ++s.count;
    ++out.total;
    s.bytes += m->data.size();
    const std::string what = path + ": " + s.info.name + " message at log time " + std::to_string(m->log_time_ns);
    try {
      if (!s.frame_read && startsWithHeader(s.info.type)) {
        bag::CdrReader cdr(m->data, what);
        s.frame_id = cdr.readHeader().frame_id;
        s.frame_read = true;
      }
      if (s.info.type == bag::kTfMessageType)
        for (const auto& t : bag::decodeTfMessage(m->data, what))
          out.tf.try_emplace({t.parent_frame, t.child_frame}, t, s.info.name);
      if (!model_read[m->topic]) {
        model_read[m->topic] = true;
        if (const auto type = bag::packetMessageType(s.info.type)) {
          guessFromPackets(s, *type, m->data, m->log_time_ns, what);
        } else {
          const auto cloud = bag::decodePointCloud2(m->data, what);
          std::size_t rings = 0;
          for (const auto r : cloud.scan.ring) rings = std::max<std::size_t>(rings, std::size_t(r) + 1);
          s.cloud_points = cloud.scan.size();
          s.model = bag::guessModelFromCloud(rings, s.frame_id + " " + s.info.name);
        }
      }
    } catch (const bag::BagError& e) {
      ++out.malformed;
      out.last_malformed = e.what();
    }
  }
  // Topics that never had a message.
  for (std::size_t i = out.topics.size(); i < bag.topics().size(); ++i) {
    BagTopicSummary t;
    t.info = bag.topics()[i];
    t.lidar = bag::packetMessageType(t.info.type) || t.info.type == bag::kPointCloud2Type;
    out.topics.push_back(t);
  }
  out.files = bag.files().size();
  out.warnings = bag.warnings();
  return out;
}

void printBagSummary(const BagSummary& summary) {
  TimeNs first = 0, last = 0;
  bool any = false;
  for (const auto& s : summary.topics) {
    if (s.count == 0) continue;
    first = any ? std::min(first, s.first) : s.first;
    last = any ? std::max(last, s.last) : s.last;
    any = true;
  }
  std::cout << "bag " << summary.path << ": " << summary.files << " file(s), " << summary.topics.size() << " topics, "
            << summary.total << " messages";
  if (any)
    std::cout << ", start " << first << " ns, duration " << std::fixed << std::setprecision(3) << toSeconds(last - first)
              << " s";
  std::cout << std::endl;
  std::printf("%-44s %-40s %9s %12s %10s  %s\n", "topic", "type", "count", "rate_hz", "MB", "frame_id");
  for (const auto& s : summary.topics)
    std::printf("%-44s %-40s %9llu %12.4g %10.3f  %s\n", s.info.name.c_str(), s.info.type.c_str(),
                (unsigned long long)s.count, s.rateHz(), double(s.bytes) / 1e6,
                s.frame_id.empty() ? "-" : s.frame_id.c_str());
  std::fflush(stdout);
  for (const auto& [edge, t] : summary.tf)
    std::cout << "tf " << edge.first << " -> " << edge.second << "  (" << t.second << ")\n";
  for (const auto& w : summary.warnings) std::cerr << "warning: " << w << '\n';
  if (summary.malformed)
    std::cerr << "warning: " << summary.malformed << " messages could not be read, last: " << summary.last_malformed
              << '\n';
}

}  // namespace rigcal::app
