#pragma once
// Cuts the stream of decoded packets into full sweeps. A sweep ends where the sensor's own frame id
// changes (Ouster), or else where the rotor azimuth crosses the cut angle (Velodyne, Hesai). Sweeps
// that straddle packets are handled point by point; a gap in time also ends a sweep.
// Packets may arrive slightly out of order (UDP): a small reorder window holds the latest
// `reorder_window` data packets sorted by DecodedPacket::order_key and releases the oldest when it is
// full (all of them on flush). A packet older than one already released is dropped and counted; more
// such packets in a row than the window holds mean the key restarted (sensor reboot, counter wrap), and
// ordering starts afresh. Steady state allocates nothing: the window's packet buffers are reused.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/core/scan.hpp"
#include "rigcal/drivers/packet_decoder.hpp"

namespace rigcal::drivers {

struct AssemblerConfig {
  double cut_angle_deg = 0.0;           // azimuth at which a sweep starts, in [0, 360)
  TimeNs max_packet_gap_ns = 200 * kNsPerMs;  // a silence this long ends the sweep in progress
  std::size_t min_points = 1;           // shorter sweeps (e.g. empty) are not emitted
  std::size_t reorder_window = 8;       // data packets held to undo reordering; 0 = none
};

struct AssemblerStats {
  std::uint64_t packets = 0;
  std::uint64_t malformed = 0;
  std::uint64_t ignored = 0;
  std::uint64_t lost_packets = 0;
  std::uint64_t scans = 0;
  std::uint64_t reordered = 0;          // data packets that arrived after one with a larger order_key
  std::uint64_t late_dropped = 0;       // data packets older than one already released: dropped
  std::uint64_t key_resets = 0;         // order_key went back for good (more late packets in a row
                                        // than the window): ordering restarted from there
  std::string last_error;               // the latest malformed packet's reason
};

class ScanAssembler {
 public:
  using ScanCallback = std::function<void(Scan&&)>;

  ScanAssembler(std::string sensor_id, AssemblerConfig config, ScanCallback on_scan);

  /// Feeds one decoded packet; completed sweeps are passed to the callback, in order.
  void add(const DecodedPacket& packet);
  /// Same, without copying the points: `packet` is swapped with a recycled buffer of the reorder
  /// window (its content afterwards is unspecified; decoders reset() it before decoding).
  void add(DecodedPacket&& packet);
  /// End of input: releases the reorder window and emits the sweep in progress (a partial sweep is
  /// still a sweep).
  void flush();
  [[nodiscard]] const AssemblerStats& stats() const { return stats_; }
  /// Receive time minus last firing of the latest packet with points and a receive time that went into
  /// a sweep (read it in the scan callback: a packet of the sweep just completed, or the one that ended it).
  /// The sensor's clock lag, free of how long a sweep waits to be cut and released from the reorder window
  /// (up to reorder_window + 1 packets: 12 ms for an OS1-64, 1 ms for a VLS-128).
  [[nodiscard]] std::optional<TimeNs> lastPacketLagNs() const { return last_packet_lag_ns_; }

 private:
  [[nodiscard]] bool crossesCut(float from_deg, float to_deg) const;
  bool admit(const DecodedPacket& packet);  // counts; false when the packet goes no further
  void hold(std::size_t slot);              // inserts a filled slot into the window
  void releaseOldest();
  void process(const DecodedPacket& packet);
  void noteLag(const DecodedPacket& packet);
  void emit();

  std::string sensor_id_;
  AssemblerConfig config_;
  ScanCallback on_scan_;
  AssemblerStats stats_;

  std::vector<Point> pending_;
  std::uint32_t pending_lost_ = 0;
  std::optional<float> last_azimuth_;
  std::optional<std::uint64_t> frame_id_;
  std::optional<TimeNs> last_packet_time_;
  std::optional<TimeNs> last_packet_lag_ns_;
  std::uint64_t sequence_ = 0;

  // Reorder window: slots_ holds reorder_window + 1 reusable packets; window_ lists the held slots in
  // order_key order (stable for equal keys), free_ the unused ones.
  std::vector<DecodedPacket> slots_;
  std::vector<std::size_t> window_;
  std::vector<std::size_t> free_;
  std::optional<std::uint64_t> released_key_;  // order_key of the latest released packet
  std::optional<std::uint64_t> max_key_;       // largest order_key seen
  std::size_t consecutive_late_ = 0;
};

}  // namespace rigcal::drivers
