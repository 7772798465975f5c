#pragma once
// Turns a recording (a pcap and its rig) into bag topics, the two ways drivers record lidars: the raw
// packets (nebula_msgs/NebulaPackets, the same payloads and receive stamps as the pcap) and the decoded
// sweeps (sensor_msgs/PointCloud2 with x y z intensity ring and a u32 per-point time `t`); plus
// /tf_static and nav_msgs/Odometry. Message layouts as in bag/'s decoders, written with CdrWriter.
#include <Eigen/Geometry>

#include <atomic>
#include <string>
#include <vector>

#include "cdr_test_writer.hpp"
#include "rigcal/config/rig_config.hpp"
#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/pipeline/sensor_driver.hpp"
#include "sqlite_bag_writer.hpp"

namespace rigcal::bag::test {

inline constexpr std::size_t kPacketsPerMessage = 32;

/// The sensor's packets of `pcap` (filtered as its driver filters them) as NebulaPackets messages.
inline std::size_t writePacketTopic(SqliteBagWriter& bag, const std::string& topic, const config::SensorConfig& s,
                                    const std::filesystem::path& pcap) {
  const int id = bag.topic(topic, "nebula_msgs/msg/NebulaPackets");
  drivers::PacketFilter filter;
  filter.destination_port = s.source.port;
  filter.info_port = s.source.info_port;
  if (s.source.address) filter.source_address = drivers::parseIpv4(*s.source.address);
  drivers::PcapSource source(pcap, filter);
  std::vector<std::pair<TimeNs, std::vector<std::uint8_t>>> pending;
  std::size_t messages = 0;
  const auto flush = [&] {
    if (pending.empty()) return;
    CdrWriter w;
    w.putHeader(pending.front().first, s.name);
    w.put(std::uint32_t(pending.size()));
    for (const auto& [stamp, data] : pending) {
      w.put(std::int32_t(stamp / 1'000'000'000)).put(std::uint32_t(stamp % 1'000'000'000));
      w.put(std::uint32_t(data.size())).putBytes(data);
    }
    bag.write(id, pending.back().first, w.bytes());
    pending.clear();
    ++messages;
  };
  while (auto p = source.next()) {
    pending.emplace_back(p->receive_ns, std::vector<std::uint8_t>(p->payload.begin(), p->payload.end()));
    if (pending.size() == kPacketsPerMessage) flush();
  }
  flush();
  return messages;
}

/// One sweep as a PointCloud2 (unorganised; t = point time − stamp in ns, as ouster-ros writes it).
inline std::vector<std::uint8_t> pointCloud2(const Scan& scan, const std::string& frame) {
  CdrWriter w;
  w.putHeader(scan.stamp_ns, frame);
  w.put(std::uint32_t(1)).put(std::uint32_t(scan.size()));
  struct F {
    const char* name;
    std::uint32_t offset;
    std::uint8_t datatype;
  };
  const F fields[] = {{"x", 0, 7}, {"y", 4, 7}, {"z", 8, 7}, {"intensity", 12, 7}, {"ring", 16, 4}, {"t", 20, 6}};
  w.put(std::uint32_t(std::size(fields)));
  for (const auto& f : fields) w.putString(f.name).put(f.offset).put(f.datatype).put(std::uint32_t(1));
  constexpr std::uint32_t kStep = 24;
  w.put(std::uint8_t(0)).put(kStep).put(std::uint32_t(kStep * scan.size()));
  std::vector<std::uint8_t> data(kStep * scan.size());
  for (std::size_t i = 0; i < scan.size(); ++i) {
    std::uint8_t* p = data.data() + i * kStep;
    std::memcpy(p, &scan.x[i], 4);
    std::memcpy(p + 4, &scan.y[i], 4);
    std::memcpy(p + 8, &scan.z[i], 4);
    std::memcpy(p + 12, &scan.intensity[i], 4);
    std::memcpy(p + 16, &scan.ring[i], 2);
    std::memcpy(p + 20, &scan.offset_ns[i], 4);
  }
  w.put(std::uint32_t(data.size())).putBytes(data).put(std::uint8_t(1));
  return w.bytes();
}

/// The sensor's sweeps, decoded from `pcap` by its driver, as PointCloud2 messages logged at each sweep's end.
inline std::size_t writeCloudTopic(SqliteBagWriter& bag, const std::string& topic, const config::SensorConfig& s,
                                   const std::filesystem::path& pcap) {
  const int id = bag.topic(topic, "sensor_msgs/msg/PointCloud2");
  std::size_t messages = 0;
  const std::atomic<bool> stop{false};
  pipeline::DriverInput input;
  input.pcap = pcap;
  pipeline::SensorDriver driver(s, input, stop, [&](Scan&& scan) {
    if (scan.empty()) return;
    const TimeNs end = scan.stamp_ns + *std::max_element(scan.offset_ns.begin(), scan.offset_ns.end());
    bag.write(id, end, pointCloud2(scan, s.name));
    ++messages;
  });
  driver.run();
  return messages;
}

inline std::vector<std::uint8_t> putTransform(CdrWriter& w, TimeNs stamp, const std::string& parent,
                                              const std::string& child, const Pose& T) {
  w.putHeader(stamp, parent).putString(child);
  const Eigen::Quaterniond q(T.linear());
  for (double v : {T.translation().x(), T.translation().y(), T.translation().z(), q.x(), q.y(), q.z(), q.w()}) w.put(v);
  return w.bytes();
}

/// /tf_static: one message holding every {parent, child, T_parent_child}.
struct TfEdge {
  std::string parent, child;
  Pose T_parent_child;
};
inline void writeTfStatic(SqliteBagWriter& bag, TimeNs stamp, const std::vector<TfEdge>& edges) {
  const int id = bag.topic("/tf_static", "tf2_msgs/msg/TFMessage");
  CdrWriter w;
  w.put(std::uint32_t(edges.size()));
  for (const auto& e : edges) putTransform(w, stamp, e.parent, e.child, e.T_parent_child);
  bag.write(id, stamp, w.bytes());
}

/// nav_msgs/Odometry: Header, child_frame_id, PoseWithCovariance, TwistWithCovariance (zeros).
inline std::vector<std::uint8_t> odometry(TimeNs stamp, const Pose& T_world_body) {
  CdrWriter w;
  w.putHeader(stamp, "map").putString("base_link");
  const Eigen::Quaterniond q(T_world_body.linear());
  const Eigen::Vector3d t = T_world_body.translation();
  for (double v : {t.x(), t.y(), t.z(), q.x(), q.y(), q.z(), q.w()}) w.put(v);
  for (int i = 0; i < 36 + 6 + 36; ++i) w.put(0.0);
  return w.bytes();
}

}  // namespace rigcal::bag::test
