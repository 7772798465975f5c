#include "rigcal/sim/bag_recording.hpp"

#include <algorithm>
#include <charconv>
#include <limits>

#include "rigcal/bag/odometry_encoder.hpp"
#include "rigcal/bag/packet_scan_encoder.hpp"
#include "rigcal/bag/point_cloud2_encoder.hpp"
#include "rigcal/bag/point_cloud2_message.hpp"
#include "rigcal/bag/ros_message_definitions.hpp"
#include "rigcal/bag/tf_message_encoder.hpp"
#include "rigcal/sim/outputs.hpp"
#include "rigcal/sim/recording.hpp"
#include "text_format.hpp"

namespace rigcal::sim {

namespace {

// The double poses.csv's text reads back as, so /odom and the CSV give calibrate-pose the same numbers.
double asWritten(double v, int decimals) {
  const std::string text = detail::fixed(v, decimals);
  double out = 0;
  std::from_chars(text.data(), text.data() + text.size(), out);
  return out;
}

std::uint16_t schemaFor(bag::McapWriter& writer, const std::string& type) {
  return writer.addSchema(type, "ros2msg", bag::rosMessageDefinition(type));
}

}  // namespace

std::string packetTopic(const SensorSpec& sensor) { return "/" + sensor.name + "/packets"; }
std::string pointsTopic(const SensorSpec& sensor) { return "/" + sensor.name + "/points"; }

bag::PacketMessageType packetMessageTypeFor(const LidarModel& model) {
  switch (model.vendor) {
    case LidarVendor::kVelodyne: return bag::PacketMessageType::kVelodyneScan;
    case LidarVendor::kHesai: return bag::PacketMessageType::kPandarScan;
    case LidarVendor::kRobosense: return bag::PacketMessageType::kRobosenseScan;
    case LidarVendor::kOuster: return bag::PacketMessageType::kOusterPacket;
  }
  return bag::PacketMessageType::kNebulaPackets;
}

BagRecording::BagRecording(const Simulation& sim, const std::filesystem::path& packets_bag,
                           const std::filesystem::path& points_bag, const bag::McapWriterOptions& options,
                           SimulationSink* also)
    : sim_(sim), also_(also), pending_(sim.sensorCount()) {
  encodeOdometry();
  const auto& sensors = sim.scenario().sensors;
  for (std::size_t i = 0; i < sim.sensorCount(); ++i) {
    types_.push_back(packetMessageTypeFor(sim.model(i)));
    info_ports_.push_back(infoPort(sensors[i], sim.model(i)));
  }
  if (!packets_bag.empty()) {
    packets_.emplace();
    packets_->writer = std::make_unique<bag::McapWriter>(packets_bag, options);
    std::map<bag::PacketMessageType, std::uint16_t> schemas;
    for (std::size_t i = 0; i < sensors.size(); ++i) {
      if (!schemas.count(types_[i]))
        schemas[types_[i]] = schemaFor(*packets_->writer, std::string(bag::packetMessageTypeName(types_[i])));
      packets_->sensor_channels.push_back(packets_->writer->addChannel(packetTopic(sensors[i]), schemas[types_[i]]));
    }
    writeCommonTopics(*packets_->writer);
  }
  if (!points_bag.empty()) {
    points_.emplace();
    points_->writer = std::make_unique<bag::McapWriter>(points_bag, options);
    const auto schema = schemaFor(*points_->writer, bag::kPointCloud2Type);
    for (const auto& s : sensors) points_->sensor_channels.push_back(points_->writer->addChannel(pointsTopic(s), schema));
    writeCommonTopics(*points_->writer);
  }
}

BagRecording::~BagRecording() = default;

void BagRecording::writeCommonTopics(bag::McapWriter& writer) {
  const TimeNs start = sim_.startTime();
  std::vector<bag::StampedTransform> tf;
  for (const auto& [name, T] : perturbedExtrinsics(sim_.scenario())) tf.push_back({start, "base_link", name, T});
  const auto tf_channel = writer.addChannel(kTfStaticTopic, schemaFor(writer, bag::kTfMessageType), "cdr",
                                            {{"offered_qos_profiles", "- durability: transient_local"}});
  writer.write(tf_channel, start, bag::encodeTfMessage(tf));

  const auto odom = writer.addChannel(kOdometryTopic, schemaFor(writer, bag::kOdometryType));
  odometry_channels_.emplace_back(packets_ && &writer == packets_->writer.get() ? &*packets_ : &*points_, odom);
}

void BagRecording::writeOdometry(TimeNs until) {
  // Compared on the true clock (stamps are on the pose sensor's): a shortened run (--duration) ends
  // /odom where the lidars end.
  const TimeNs offset = sim_.scenario().pose_sensor ? sim_.scenario().pose_sensor->clock_offset_ns : 0;
  for (; next_odometry_ < odometry_.size() && odometry_[next_odometry_].first - offset <= until; ++next_odometry_)
    for (const auto& [output, channel] : odometry_channels_)
      output->writer->write(channel, odometry_[next_odometry_].first, odometry_[next_odometry_].second);
}

void BagRecording::encodeOdometry() {
  const std::string child = poseFrame(sim_);
  for (const PoseSample& p : poseSamples(sim_)) {
    bag::OdometrySample o;
    o.stamp_ns = p.stamp_ns;
    Eigen::Quaterniond q(p.T_world_pose.linear());
    if (q.w() < 0) q.coeffs() = -q.coeffs();
    const Eigen::Quaterniond written(asWritten(q.w(), 9), asWritten(q.x(), 9), asWritten(q.y(), 9),
                                     asWritten(q.z(), 9));
    o.T_world_body = Pose::Identity();
    o.T_world_body.linear() = written.normalized().toRotationMatrix();
    for (int k = 0; k < 3; ++k) o.T_world_body.translation()[k] = asWritten(p.T_world_pose.translation()[k], 6);
    odometry_.emplace_back(p.stamp_ns, bag::encodeOdometry(o, kWorldFrame, child));
  }
}

void BagRecording::onFirings(std::size_t sensor, const FiringBatch& batch) {
  if (also_) also_->onFirings(sensor, batch);
}

void BagRecording::onChunkEnd(TimeNs true_time) {
  writeOdometry(true_time);
  last_chunk_end_ = true_time;
  if (also_) also_->onChunkEnd(true_time);
}

void BagRecording::onScan(SimulatedScan&& scan) {
  if (points_ && !scan.scan.empty()) {
    const auto& sensor = sim_.scenario().sensors[scan.sensor];
    const TimeNs log_time = *std::max_element(scan.true_time_ns.begin(), scan.true_time_ns.end());
    points_->writer->write(points_->sensor_channels[scan.sensor], log_time,
                           bag::encodePointCloud2(scan.scan, sensor.name, bag::PointCloud2Layout::kRigcal));
    ++cloud_messages_;
  }
  if (also_) also_->onScan(std::move(scan));
}

void BagRecording::onDatagram(std::size_t sensor, std::uint16_t port, std::span<const std::uint8_t> payload,
                              TimeNs capture_ns) {
  if (!packets_) return;
  PendingScan& p = pending_[sensor];
  // A scan message holds one rotation period of packets, as the drivers publish them.
  if (!p.stamps.empty() && capture_ns - p.stamps.front() >= sim_.model(sensor).framePeriodNs()) flushScan(sensor);
  p.payloads.emplace_back(payload.begin(), payload.end());
  p.stamps.push_back(capture_ns);
  p.difop.push_back(info_ports_[sensor] != 0 && port == info_ports_[sensor]);
  if (types_[sensor] == bag::PacketMessageType::kOusterPacket) flushScan(sensor);  // one packet per message
}

void BagRecording::flushScan(std::size_t sensor) {
  PendingScan& p = pending_[sensor];
  if (p.stamps.empty()) return;
  std::vector<bag::ScanPacket> packets;
  for (std::size_t i = 0; i < p.stamps.size(); ++i) packets.push_back({p.stamps[i], p.payloads[i], p.difop[i]});
  const auto& name = sim_.scenario().sensors[sensor].name;
  packets_->writer->write(packets_->sensor_channels[sensor], p.stamps.back(),
                          bag::encodePacketMessage(types_[sensor], p.stamps.front(), name, packets));
  ++packet_messages_;
  p = PendingScan{};
}

void BagRecording::close() {
  writeOdometry(last_chunk_end_);
  if (packets_) {
    for (std::size_t i = 0; i < pending_.size(); ++i) flushScan(i);
    packets_->writer->close();
  }
  if (points_) points_->writer->close();
}

}  // namespace rigcal::sim
