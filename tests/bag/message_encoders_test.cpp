// The CDR encoders against our decoders: packet scans of every family, PointCloud2 in every layout
// (per-point times exact for the integer-ns fields, within the float's resolution otherwise), TFMessage,
// and Odometry read back field by field.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "rigcal/bag/cdr_reader.hpp"
#include "rigcal/bag/odometry_encoder.hpp"
#include "rigcal/bag/packet_scan_encoder.hpp"
#include "rigcal/bag/point_cloud2_encoder.hpp"
#include "rigcal/bag/point_cloud2_message.hpp"
#include "rigcal/bag/tf_message_encoder.hpp"

namespace rigcal::bag {
namespace {

using Bytes = std::vector<std::uint8_t>;

TEST(PacketScanEncoder, EveryFamilyDecodesToTheSamePackets) {
  std::mt19937 rng(3);
  for (const auto type : {PacketMessageType::kVelodyneScan, PacketMessageType::kPandarScan,
                          PacketMessageType::kRobosenseScan, PacketMessageType::kNebulaPackets,
                          PacketMessageType::kOusterPacket}) {
    const std::size_t count = type == PacketMessageType::kOusterPacket ? 1 : 5;
    std::vector<Bytes> payloads;
    std::vector<ScanPacket> packets;
    for (std::size_t i = 0; i < count; ++i) {
      const std::size_t size = type == PacketMessageType::kVelodyneScan ? 1206 : 100 + rng() % 1300;
      payloads.emplace_back(size);
      for (auto& b : payloads.back()) b = std::uint8_t(rng());
    }
    for (std::size_t i = 0; i < count; ++i)
      packets.push_back({1'700'000'000'123'456'789 + TimeNs(i) * 1'000'000, payloads[i],
                         type == PacketMessageType::kRobosenseScan && i == 2});
    const Bytes message = encodePacketMessage(type, 1'700'000'000'000'000'007, "lidar_top", packets);
    EXPECT_TRUE(packetMessageType(packetMessageTypeName(type)).has_value());
    std::vector<ScanPacket> decoded;
    const TimeNs log_time = 42;
    decodePacketMessage(type, message, log_time, "test", decoded);
    ASSERT_EQ(decoded.size(), count) << packetMessageTypeName(type);
    for (std::size_t i = 0; i < count; ++i) {
      EXPECT_TRUE(std::equal(decoded[i].data.begin(), decoded[i].data.end(), payloads[i].begin(), payloads[i].end()));
      EXPECT_EQ(decoded[i].stamp_ns, type == PacketMessageType::kOusterPacket ? log_time : packets[i].stamp_ns);
      EXPECT_EQ(decoded[i].is_difop, packets[i].is_difop);
    }
    if (type != PacketMessageType::kOusterPacket) {
      CdrReader cdr(message, "header");
      const RosHeader h = cdr.readHeader();
      EXPECT_EQ(h.stamp_ns, 1'700'000'000'000'000'007);
      EXPECT_EQ(h.frame_id, "lidar_top");
    }
  }
}

TEST(PacketScanEncoder, RefusesPacketsThatDoNotFit) {
  const Bytes big(1501, 0), short_velodyne(1000, 0);
  const ScanPacket too_big{0, big, false}, wrong{0, short_velodyne, false};
  EXPECT_THROW(encodePacketMessage(PacketMessageType::kPandarScan, 0, "f", {&too_big, 1}), std::invalid_argument);
  EXPECT_THROW(encodePacketMessage(PacketMessageType::kVelodyneScan, 0, "f", {&wrong, 1}), std::invalid_argument);
  EXPECT_THROW(encodePacketMessage(PacketMessageType::kOusterPacket, 0, "f", {}), std::invalid_argument);
}

Scan randomScan(std::size_t n, TimeNs stamp) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<float> coord(-80.f, 80.f);
  Scan s;
  s.stamp_ns = stamp;
  for (std::size_t i = 0; i < n; ++i) {
    Point p;
    p.x = coord(rng);
    p.y = coord(rng);
    p.z = coord(rng) / 10;
    p.intensity = float(rng() % 256);
    p.ring = std::uint16_t(rng() % 128);
    p.return_index = std::uint8_t(rng() % 2);
    p.time_ns = stamp + TimeNs(rng() % 100'000'000);
    s.push_back(p);
  }
  return s;
}

TEST(PointCloud2Encoder, EveryLayoutReadsBackPointForPoint) {
  const TimeNs stamp = 1'700'000'000'250'000'000;
  const Scan scan = randomScan(2000, stamp);
  for (const auto layout : {PointCloud2Layout::kVelodyne, PointCloud2Layout::kOuster, PointCloud2Layout::kHesai,
                            PointCloud2Layout::kLivox, PointCloud2Layout::kNebula, PointCloud2Layout::kRigcal}) {
    const std::string name(pointCloud2LayoutName(layout));
    const DecodedCloud cloud = decodePointCloud2(encodePointCloud2(scan, "lidar", layout), name);
    EXPECT_EQ(cloud.frame_id, "lidar");
    EXPECT_EQ(cloud.header_stamp_ns, stamp);
    ASSERT_EQ(cloud.scan.size(), scan.size()) << name;
    EXPECT_FALSE(cloud.time_field.empty()) << name;
    // Integer-ns fields are exact; f32 seconds after the stamp resolve ~8 ns at 0.1 s; f64 absolute
    // seconds resolve ~0.24 us at 1.7e9 s.
    const TimeNs tolerance = layout == PointCloud2Layout::kVelodyne ? 10 : layout == PointCloud2Layout::kHesai ? 500 : 0;
    for (std::size_t i = 0; i < scan.size(); ++i) {
      ASSERT_EQ(cloud.scan.x[i], scan.x[i]) << name << " point " << i;
      ASSERT_EQ(cloud.scan.y[i], scan.y[i]);
      ASSERT_EQ(cloud.scan.z[i], scan.z[i]);
      ASSERT_EQ(cloud.scan.intensity[i], scan.intensity[i]);
      if (layout != PointCloud2Layout::kLivox) {
        ASSERT_EQ(cloud.scan.ring[i], scan.ring[i]);
      }
      ASSERT_LE(std::llabs(cloud.scan.pointTime(i) - scan.pointTime(i)), tolerance) << name << " point " << i;
    }
  }
}

TEST(PointCloud2Encoder, EmptyScan) {
  Scan empty;
  empty.stamp_ns = 5;
  const DecodedCloud cloud = decodePointCloud2(encodePointCloud2(empty, "f", PointCloud2Layout::kRigcal), "empty");
  EXPECT_TRUE(cloud.scan.empty());
  EXPECT_EQ(cloud.header_stamp_ns, 5);
}

TEST(TfMessageEncoder, ReadsBackEveryTransform) {
  std::vector<StampedTransform> tf(3);
  for (std::size_t i = 0; i < tf.size(); ++i) {
    tf[i].stamp_ns = TimeNs(i) * 7;
    tf[i].parent_frame = i ? "base_link" : "map";
    tf[i].child_frame = "frame_" + std::to_string(i);
    tf[i].T_parent_child = fromXyzRpy({0.1 * double(i), -1.5, 2.0, 0.2, -0.3 * double(i), 1.1});
  }
  const auto back = decodeTfMessage(encodeTfMessage(tf), "tf");
  ASSERT_EQ(back.size(), tf.size());
  for (std::size_t i = 0; i < tf.size(); ++i) {
    EXPECT_EQ(back[i].stamp_ns, tf[i].stamp_ns);
    EXPECT_EQ(back[i].parent_frame, tf[i].parent_frame);
    EXPECT_EQ(back[i].child_frame, tf[i].child_frame);
    EXPECT_TRUE(back[i].T_parent_child.isApprox(tf[i].T_parent_child, 1e-12));
  }
}

TEST(OdometryEncoder, FieldsAtTheirCdrOffsets) {
  OdometrySample s;
  s.stamp_ns = 1'700'000'000'000'000'001;
  s.T_world_body = fromXyzRpy({10, -20, 0.5, 0.01, 0.02, 2.5});
  s.linear_velocity = {3, 0.1, 0};
  s.angular_velocity = {0, 0, 0.2};
  s.pose_covariance[0] = 0.25;
  s.twist_covariance[35] = 0.5;
  const Bytes message = encodeOdometry(s, "odom", "base_link");
  CdrReader cdr(message, "odometry");
  const RosHeader h = cdr.readHeader();
  EXPECT_EQ(h.stamp_ns, s.stamp_ns);
  EXPECT_EQ(h.frame_id, "odom");
  EXPECT_EQ(cdr.readString("child_frame_id"), "base_link");
  Eigen::Vector3d p;
  for (int i = 0; i < 3; ++i) p[i] = cdr.read<double>("position");
  double q[4];
  for (double& v : q) v = cdr.read<double>("orientation");
  EXPECT_TRUE(p.isApprox(s.T_world_body.translation()));
  EXPECT_TRUE(Eigen::Quaterniond(q[3], q[0], q[1], q[2]).toRotationMatrix().isApprox(s.T_world_body.linear(), 1e-12));
  EXPECT_EQ(cdr.read<double>("pose.covariance"), 0.25);
  for (int i = 1; i < 36; ++i) cdr.read<double>("pose.covariance");
  for (int i = 0; i < 3; ++i) EXPECT_EQ(cdr.read<double>("twist.linear"), s.linear_velocity[i]);
  for (int i = 0; i < 3; ++i) EXPECT_EQ(cdr.read<double>("twist.angular"), s.angular_velocity[i]);
  for (int i = 0; i < 35; ++i) cdr.read<double>("twist.covariance");
  EXPECT_EQ(cdr.read<double>("twist.covariance"), 0.5);
  EXPECT_EQ(cdr.remaining(), 0u);
}

}  // namespace
}  // namespace rigcal::bag
