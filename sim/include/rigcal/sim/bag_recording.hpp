#pragma once
// `rigcal sim --format mcap`: the recording as ROS 2 MCAP bags, in the two forms users bring.
//  - packet form (recording.mcap): each sensor's datagrams, stamped with their capture time, as its
//    vendor driver's scan message on /<sensor>/packets (Velodyne VelodyneScan, Hesai PandarScan,
//    RoboSense RobosenseScan with DIFOP flagged, Ouster one PacketMsg per packet); a scan message
//    gathers one rotation period of packets.
//  - cloud form (recording_points.mcap): each simulated sweep as sensor_msgs/PointCloud2 on
//    /<sensor>/points (frame_id = sensor name; fields x y z intensity f32, t u32 ns, ring u16,
//    return_type u8; sensor-clock stamps), logged at the sweep's last true point time.
// Both carry /tf_static (base_link -> each lidar: the rig.yaml initial extrinsics, i.e. the truth
// perturbed as the scenario says) and /odom (nav_msgs/Odometry, frame "map", child the pose sensor or
// base_link: exactly the samples of poses.csv, positions and quaternions rounded as its text is).
#include <filesystem>
#include <memory>
#include <optional>
#include <vector>

#include "rigcal/bag/mcap_writer.hpp"
#include "rigcal/bag/packet_scan_message.hpp"
#include "rigcal/sim/recording_writer.hpp"
#include "rigcal/sim/simulation.hpp"

namespace rigcal::sim {

inline constexpr const char* kTfStaticTopic = "/tf_static";
inline constexpr const char* kOdometryTopic = "/odom";
inline constexpr const char* kWorldFrame = "map";

/// "/<sensor>/packets" and "/<sensor>/points".
std::string packetTopic(const SensorSpec& sensor);
std::string pointsTopic(const SensorSpec& sensor);
/// The scan message family a sensor's packets are recorded as.
bag::PacketMessageType packetMessageTypeFor(const LidarModel& model);

class BagRecording final : public SimulationSink, public DatagramObserver {
 public:
  /// Either path may be empty (that form is not written). `also` (optional) receives every firing and
  /// sweep after this sink. Throws std::runtime_error when a file cannot be created.
  BagRecording(const Simulation& sim, const std::filesystem::path& packets_bag,
               const std::filesystem::path& points_bag, const bag::McapWriterOptions& options,
               SimulationSink* also = nullptr);
  ~BagRecording() override;

  void onFirings(std::size_t sensor, const FiringBatch& batch) override;
  void onScan(SimulatedScan&& scan) override;
  void onChunkEnd(TimeNs true_time) override;
  void onDatagram(std::size_t sensor, std::uint16_t port, std::span<const std::uint8_t> payload,
                  TimeNs capture_ns) override;

  /// Writes what is pending and closes both files (they appear only then).
  void close();
  [[nodiscard]] std::uint64_t packetMessages() const { return packet_messages_; }
  [[nodiscard]] std::uint64_t cloudMessages() const { return cloud_messages_; }

 private:
  struct PendingScan {
    std::vector<std::vector<std::uint8_t>> payloads;
    std::vector<TimeNs> stamps;
    std::vector<bool> difop;
  };
  struct Output {
    std::unique_ptr<bag::McapWriter> writer;
    std::vector<std::uint16_t> sensor_channels;
  };
  void encodeOdometry();
  void writeCommonTopics(bag::McapWriter& writer);
  /// /odom samples up to `until`, interleaved with the lidar messages so chunks stay short in time.
  void writeOdometry(TimeNs until);
  void flushScan(std::size_t sensor);

  const Simulation& sim_;
  SimulationSink* also_;
  std::optional<Output> packets_, points_;
  std::vector<PendingScan> pending_;
  std::vector<bag::PacketMessageType> types_;
  std::vector<std::uint16_t> info_ports_;
  std::vector<std::pair<TimeNs, std::vector<std::uint8_t>>> odometry_;  // (stamp, message)
  std::size_t next_odometry_ = 0;
  TimeNs last_chunk_end_ = 0;
  std::vector<std::pair<Output*, std::uint16_t>> odometry_channels_;
  std::uint64_t packet_messages_ = 0, cloud_messages_ = 0;
};

}  // namespace rigcal::sim
