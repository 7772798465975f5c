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

#include "rigcal/config/rig_config.hpp"
#include "rigcal/drivers/packet_decoder.hpp"
#include "rigcal/drivers/packet_family.hpp"
#include "rigcal/drivers/packet_source.hpp"
#include "rigcal/drivers/scan_assembler.hpp"

namespace rigcal::pipeline {

struct DriverInput {
  std::optional<std::filesystem::path> pcap;  // empty: live UDP on the sensor's port
  double rate = 0.0;                          // pcap only: 1.0 = recorded timing, 0 = as fast as possible
};

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

  /// Runs until the pcap ends or `stop` is set; calls `idle` whenever a live source timed out.
  void run(const std::function<void()>& idle = {});
  [[nodiscard]] std::size_t maxPointsPerScan() const { return decoder_->maxPointsPerScan(); }
  [[nodiscard]] const drivers::AssemblerStats& assemblerStats() const { return assembler_.stats(); }
  [[nodiscard]] const drivers::SourceStats& sourceStats() const { return source_->stats(); }
  [[nodiscard]] std::string warning() const { return source_->warning(); }
  /// The median over sweeps of (capture / receive time of the packet that closed the sweep − the sensor's
  /// time of the sweep's last point), in ms; nullopt before the first sweep. Sensors whose clocks agree
  /// show the same lag within the network's and the assembler's few ms (see SensorClockCheck).
  [[nodiscard]] std::optional<double> clockLagMs() const;
  /// Packets of another model held back from the decoder (complete once run() returned).
  [[nodiscard]] const ForeignPackets& foreignPackets() const;
  /// The per-sweep lags behind clockLagMs() (their spread gives its uncertainty).
  [[nodiscard]] std::vector<double> clockLagSamplesMs() const;

 private:
  config::SensorConfig sensor_;
  std::unique_ptr<drivers::PacketSource> raw_source_;
  std::unique_ptr<drivers::PacketSource> source_;  // raw_source_, or a pacing wrapper around it
  std::unique_ptr<drivers::PacketDecoder> decoder_;
  drivers::ScanAssembler assembler_;
  const std::atomic<bool>& stop_;
  bool live_ = false;
  void recordLag(const Scan& scan);
  class ReceiveTimeTap;
  std::unique_ptr<ReceiveTimeTap> tap_;  // wraps source_: remembers the last packet's receive time
  mutable std::mutex lag_mutex_;
  std::vector<double> lags_ms_;  // one per sweep (the first kMaxLags)
};

}  // namespace rigcal::pipeline
