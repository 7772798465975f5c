// `rigcal inspect BAG`: what a ROS 2 bag holds, read in one streaming pass: each topic's type, message
// count, rate and frame id, and the tf tree's edges, so a user can see which topics to calibrate from.
#include <algorithm>
#include <cstdio>
#include <iomanip>
#include <iostream>
#include <map>
#include <set>

#include "../commands.hpp"
#include "../exit_codes.hpp"
#include "rigcal/bag/bag.hpp"
#include "rigcal/bag/bag_error.hpp"
#include "rigcal/bag/cdr_reader.hpp"
#include "rigcal/bag/packet_scan_message.hpp"
#include "rigcal/bag/tf_message.hpp"

namespace rigcal::app {

namespace {

struct TopicStats {
  std::uint64_t count = 0, bytes = 0;
  TimeNs first = 0, last = 0;
  std::string frame_id;
  bool frame_read = false;
};

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

void run(const std::string& path) {
  std::map<std::size_t, TopicStats> stats;
  std::set<std::pair<std::string, std::string>> tf_edges;  // parent, child
  std::map<std::pair<std::string, std::string>, std::string> tf_topic;
  std::uint64_t total = 0, malformed = 0;
  std::string last_malformed;
  std::unique_ptr<bag::Bag> bag;
  try {
    bag = std::make_unique<bag::Bag>(path);
    while (const auto m = bag->next()) {
      const auto& topic = bag->topics()[m->topic];
      TopicStats& s = stats[m->topic];
      if (s.count == 0) s.first = m->log_time_ns;
      s.last = m->log_time_ns;
      ++s.count;
      ++total;
      s.bytes += m->data.size();
      const std::string what = path + ": " + topic.name + " message at log time " + std::to_string(m->log_time_ns);
      try {
        if (!s.frame_read && startsWithHeader(topic.type)) {
          bag::CdrReader cdr(m->data, what);
          s.frame_id = cdr.readHeader().frame_id;
          s.frame_read = true;
        }
        if (topic.type == bag::kTfMessageType)
          for (const auto& t : bag::decodeTfMessage(m->data, what)) {
            tf_edges.insert({t.parent_frame, t.child_frame});
            tf_topic[{t.parent_frame, t.child_frame}] = topic.name;
          }
      } catch (const bag::BagError& e) {
        ++malformed;
        last_malformed = e.what();
      }
    }
  } catch (const bag::BagError& e) {
    throw CommandFailed(kExitInput, e.what());
  }

  TimeNs first = 0, last = 0;
  bool any = false;
  for (const auto& [topic, s] : stats) {
    first = any ? std::min(first, s.first) : s.first;
    last = any ? std::max(last, s.last) : s.last;
    any = true;
  }
  std::cout << "bag " << path << ": " << bag->files().size() << " file(s), " << bag->topics().size() << " topics, "
            << total << " messages";
  if (any)
    std::cout << ", start " << first << " ns, duration " << std::fixed << std::setprecision(3) << toSeconds(last - first)
              << " s";
  std::cout << std::endl;
  std::printf("%-44s %-40s %9s %12s %10s  %s\n", "topic", "type", "count", "rate_hz", "MB", "frame_id");
  for (std::size_t i = 0; i < bag->topics().size(); ++i) {
    const auto& t = bag->topics()[i];
    const TopicStats s = stats.count(i) ? stats.at(i) : TopicStats{};
    const double rate = s.count > 1 && s.last > s.first ? double(s.count - 1) / toSeconds(s.last - s.first) : 0.0;
    std::printf("%-44s %-40s %9llu %12.4g %10.3f  %s\n", t.name.c_str(), t.type.c_str(), (unsigned long long)s.count,
                rate, double(s.bytes) / 1e6, s.frame_id.empty() ? "-" : s.frame_id.c_str());
  }
  std::fflush(stdout);
  for (const auto& [parent, child] : tf_edges)
    std::cout << "tf " << parent << " -> " << child << "  (" << tf_topic[{parent, child}] << ")\n";
  for (const auto& w : bag->warnings()) std::cerr << "warning: " << w << '\n';
  if (malformed)
    std::cerr << "warning: " << malformed << " messages could not be read, last: " << last_malformed << '\n';
  if (total == 0) throw CommandFailed(kExitNotEnoughData, path + ": the bag holds no messages");
}

}  // namespace

void addInspectCommand(CLI::App& app) {
  auto path = std::make_shared<std::string>();
  auto* cmd = app.add_subcommand("inspect", "List a ROS 2 bag's topics, types, counts, rates, frame ids and tf edges");
  cmd->add_option("bag", *path, "rosbag2 folder, .mcap or .db3")->required();
  cmd->footer(kExitCodesHelp);
  cmd->callback([path] { run(*path); });
}

}  // namespace rigcal::app
