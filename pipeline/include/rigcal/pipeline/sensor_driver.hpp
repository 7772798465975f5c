#pragma once
// One sensor's driver as the rig file describes it: its packet source (live UDP, or a pcap filtered to
// its port and address, optionally paced at the recorded rate), its decoder and its scan assembler.
// `rigcal driver` runs one in its own process; the pipeline runs them as threads. Same code either way.
#include <atomic>
#include <filesystem>
#include <functional>
#include <memory>
#include <mutex>
#include <optional>
#include <vector>

#include "rigcal/bag/bag_cloud_source.hpp"
#include "rigcal/config/rig_config.hpp"
#include "rigcal/drivers/packet_decoder.hpp"
#include "rigcal/drivers/packet_family.hpp"
#include "rigcal/drivers/packet_source.hpp"
#include "rigcal/drivers/scan_assembler.hpp"

namespace rigcal::pipeline {

struct DriverInput {
  DriverInput() = default;
  /// `{pcap, rate}` as before bags existed (no aggregate: the bag fields need no initializer there).
  DriverInput(std::optional<std::filesystem::path> pcap_file, double replay_rate)
      : pcap(std::move(pcap_file)), rate(replay_rate) {}
  std::optional<std::filesystem::path> pcap;  // empty (and no bag): live UDP on the sensor's port
  double rate = 0.0;                          // pcap or bag: 1.0 = recorded timing, 0 = as fast as possible
  std::optional<std::filesystem::path> bag;   // a ROS 2 bag instead of a pcap
  /// With a bag: the sensor's topic (packets or PointCloud2); empty: the sensor's source.topic, else
  /// the bag's only lidar topic.
  std::string topic;
};

/// The model of a sensor whose scans come decoded, as a bag's sensor_msgs/PointCloud2 topic: no packet
/// decoder (nor calibration / metadata file) is needed.
inline constexpr const char* kPointCloud2Model = "PointCloud2";
/// Points per scan a PointCloud2 sensor's ring slot holds: an OS-128 at 2048 columns, dual return.
inline constexpr std::size_t kMaxPointCloud2Points = std::size_t(1) << 19;

/// Packets of another vendor's model that reached a sensor's port or filter (drivers::recognizePacket).
struct ForeignPackets {
  std::uint64_t packets = 0;
  drivers::PacketFamily family = drivers::PacketFamily::kUnknown;  // of the last one
  std::size_t bytes = 0;                                           // its size
  drivers::UdpEndpoint last_source;
  /// One line: how many, what they look like, from where (for the sensor `model` on `port`).
  [[nodiscard]] std::string describe(const std::string& model, std::uint16_t port) const;
};

/// The decoder settings of a rig sensor.
drivers::DecoderConfig decoderConfigFor(const config::SensorConfig& sensor);

class SensorDriver {
 public:
  /// Throws std::runtime_error (one line, naming the sensor and what is wrong) when the source or the
  /// decoder cannot be set up.
  /// `stop` (outliving the driver) ends run() early, even inside a paced wait.
  SensorDriver(const config::SensorConfig& sensor, const DriverInput& input, const std::atomic<bool>& stop,
               drivers::ScanAssembler::ScanCallback on_scan);
  ~SensorDriver();

  /// Runs until the pcap / bag ends or `stop` is set; calls `idle` whenever a live source timed out.
  void run(const std::function<void()>& idle = {});
  [[nodiscard]] std::size_t maxPointsPerScan() const {
    return decoder_ ? decoder_->maxPointsPerScan() : kMaxPointCloud2Points;
  }
  [[nodiscard]] const drivers::AssemblerStats& assemblerStats() const { return assembler_.stats(); }
  [[nodiscard]] const drivers::SourceStats& sourceStats() const;
  [[nodiscard]] std::string warning() const;
  /// With a bag: the topic read and its type ("/points (sensor_msgs/msg/PointCloud2)"); empty otherwise.
  [[nodiscard]] const std::string& bagTopic() const { return bag_topic_; }
  /// The median over sweeps of (capture / receive time of the sweep's last packet − the sensor's time of that
  /// packet's last firing), in ms (a PointCloud2 topic: log time − the cloud's last point); nullopt before
  /// the first sweep. Sensors whose clocks agree show the same lag within the network's few tenths of a ms,
  /// whatever their packet rates (the packet-clock check of `calibrate`).
  [[nodiscard]] std::optional<double> clockLagMs() const;
  /// Packets of another model held back from the decoder (complete once run() returned).
  [[nodiscard]] const ForeignPackets& foreignPackets() const;
  /// The per-sweep lags behind clockLagMs() (their spread gives its uncertainty).
  [[nodiscard]] std::vector<double> clockLagSamplesMs() const;

 private:
  config::SensorConfig sensor_;
  drivers::ScanAssembler::ScanCallback on_scan_;
  std::unique_ptr<drivers::PacketSource> raw_source_;
  std::unique_ptr<drivers::PacketSource> source_;  // raw_source_, or a pacing wrapper around it
  std::unique_ptr<drivers::PacketDecoder> decoder_;
  drivers::ScanAssembler assembler_;
  const std::atomic<bool>& stop_;
  bool live_ = false;
  std::unique_ptr<bag::BagCloudSource> clouds_;  // a PointCloud2 topic: scans without packet decoding
  double rate_ = 0.0;
  std::string bag_topic_;
  void runClouds();
  void recordLag(const Scan& scan, TimeNs receive_ns);  // a whole cloud received at receive_ns
  void recordLagMs(double lag_ms);
  class ForeignPacketFilter;
  std::unique_ptr<ForeignPacketFilter> filter_;  // wraps source_: holds back and counts other models' packets
  mutable std::mutex lag_mutex_;
  std::vector<double> lags_ms_;  // one per sweep (the first kMaxLags)
};

}  // namespace rigcal::pipeline
