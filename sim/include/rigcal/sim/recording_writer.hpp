#pragma once
// Merges every sensor's encoded packets into one capture in the order a NIC would see them: each
// sensor sends from its own address and port, a packet's send time (sensor clock) is mapped to the
// reference clock, and the NIC stamps it after a link latency and a seeded jitter.
#include <cstdint>
#include <filesystem>
#include <optional>
#include <queue>
#include <span>
#include <vector>

#include "rigcal/sim/packet_encoder.hpp"
#include "rigcal/sim/pcap_writer.hpp"

namespace rigcal::sim {

struct RecordingSensor {
  NetEndpoint source;
  NetEndpoint destination;
  TimeNs clock_offset_ns = 0;  // sensor clock = true clock + offset
};

/// Sees every datagram as it is written (e.g. to record it into a bag too), in capture order.
class DatagramObserver {
 public:
  virtual ~DatagramObserver() = default;
  /// `port`: the destination port (the sensor's data port, or its info port for RoboSense DIFOP).
  virtual void onDatagram(std::size_t sensor, std::uint16_t port, std::span<const std::uint8_t> payload,
                          TimeNs capture_ns) = 0;
};

class RecordingWriter {
 public:
  /// An empty `file` writes no pcap (only the observer sees the datagrams).
  RecordingWriter(const std::filesystem::path& file, std::vector<RecordingSensor> sensors, std::uint64_t seed,
                  DatagramObserver* observer = nullptr);

  /// Queues a sensor's packets (in its send order).
  void add(std::size_t sensor, std::vector<EncodedPacket>& packets);
  /// Writes every queued packet sent (true clock) before `true_time`, in send order. Call it once no
  /// packet sent earlier can still be produced (e.g. after every sensor's firings up to that time).
  void flushUntil(TimeNs true_time);
  /// Writes everything left and closes the file.
  void finish();
  [[nodiscard]] std::uint64_t datagrams() const { return datagrams_; }
  [[nodiscard]] std::uint64_t frames() const { return pcap_ ? pcap_->frames() : 0; }

 private:
  struct Pending {
    TimeNs send_true_ns;
    std::size_t sensor;
    std::uint64_t order;  // FIFO among equal times
    std::uint16_t port;   // destination port when not the sensor's (0)
    std::vector<std::uint8_t> payload;
  };
  struct Later {
    bool operator()(const Pending& a, const Pending& b) const {
      return a.send_true_ns != b.send_true_ns ? a.send_true_ns > b.send_true_ns
             : a.sensor != b.sensor          ? a.sensor > b.sensor
                                             : a.order > b.order;
    }
  };
  std::optional<PcapWriter> pcap_;
  DatagramObserver* observer_ = nullptr;
  std::vector<RecordingSensor> sensors_;
  NicClock nic_;
  std::priority_queue<Pending, std::vector<Pending>, Later> queue_;
  std::uint64_t order_ = 0, datagrams_ = 0;
};

/// Wire time of a UDP datagram with `payload_bytes`, fragmented at a 1500-byte MTU.
TimeNs datagramWireTimeNs(std::size_t payload_bytes);

}  // namespace rigcal::sim
