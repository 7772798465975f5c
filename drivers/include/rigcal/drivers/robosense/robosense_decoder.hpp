#pragma once
// RoboSense RS-Helios-16P decoder (MSOP data + DIFOP device information, robosense_packet.hpp).
//
// Angles: each laser's vertical angle and horizontal offset come from the DIFOP packet the sensor sends
// about once a second (port 7788; the rig's `source: {info_port: 7788}` brings it to this decoder).
// Until the first DIFOP arrives, MSOP packets are held (up to kMaxHeldPackets, ~2 s of data; older ones
// are dropped and counted) and decoded as soon as it comes; at end of input without any DIFOP they are
// dropped and counted (stats().dropped_without_difop): no scan is made with guessed angles.
//
// Geometry and timing follow the layout documented by RoboSense (rs_driver) and the Helios-16P decoder of
// nebula's RoboSense branch (commit c60082d5), whose output is our reference: a channel's azimuth is the
// block azimuth plus the firing's share of the azimuth step to the next block (truncated to 0.01°) plus
// the laser's DIFOP offset; the optical centre sits 34.98 mm from the rotation axis (x = d·cosω·cos(α+δ)
// + Rx·cos α, y = −d·cosω·sin(α+δ) − Rx·sin α, z = d·sinω). Axes: x forward, y left, z up.
// Single-return modes (strongest/last/nearest): 32 channel slots per block, laser = slot mod 16, firing
// offsets 0-99.46 µs; dual (DIFOP return mode 0): blocks come in pairs with the same firing, slot < 16 is
// the first return, the rest the second.
// Time: kSensorClock takes the MSOP header's UTC seconds + µs as the first block's firing; blocks are
// 55.56 µs apart. kHostReceive takes UdpPacket::receive_ns as the packet's last firing.
// Scan cut: every point reports its block's azimuth, so the scan is cut between whole blocks, as nebula does.
#include <array>
#include <deque>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/drivers/packet_decoder.hpp"
#include "rigcal/drivers/robosense/robosense_packet.hpp"

namespace rigcal::drivers {

class RobosenseDecoder final : public PacketDecoder {
 public:
  static constexpr std::size_t kMaxHeldPackets = 3000;

  struct Stats {
    std::uint64_t difop_packets = 0;         // DIFOP packets read
    std::uint64_t held_for_difop = 0;        // MSOP packets that waited for the first DIFOP
    std::uint64_t dropped_without_difop = 0; // MSOP packets dropped: no DIFOP came in time
  };

  /// Throws std::runtime_error (one line) for a model other than RS-Helios-16P or a calibration file.
  explicit RobosenseDecoder(const DecoderConfig& config);

  void decode(const UdpPacket& packet, DecodedPacket& out) override;
  /// End of input: MSOP packets still waiting for a DIFOP are dropped and counted.
  void flush(DecodedPacket& out) override;
  [[nodiscard]] std::string model() const override { return "RS-Helios-16P"; }
  [[nodiscard]] double scanRateHz() const override { return scan_rate_hz_; }
  [[nodiscard]] std::size_t maxPointsPerScan() const override;
  [[nodiscard]] const Stats& stats() const { return stats_; }
  [[nodiscard]] bool hasAngles() const { return info_.has_value(); }

 private:
  struct Held {
    std::vector<std::uint8_t> payload;
    TimeNs receive_ns = 0;
  };
  void applyDeviceInfo(const robosense::DeviceInfo& info);
  // Appends the points of one checked MSOP packet; returns the time of its first firing.
  TimeNs decodeMsop(const robosense::MsopView& view, TimeNs receive_ns, DecodedPacket& out);
  std::uint32_t lostBefore(std::uint32_t counter);
  std::uint64_t orderKey(const robosense::MsopView& view, TimeNs receive_ns) const;

  TimeSource time_source_;
  float min_range_m_, max_range_m_;
  std::optional<robosense::DeviceInfo> info_;
  bool dual_ = false;
  std::int32_t block_az_diff_ = 20;   // 0.01°: the azimuth step of one block at the DIFOP's rpm
  std::int64_t fov_blind_ns_ = 0;     // time across the part of the turn outside the FOV
  std::array<float, robosense::kChannelsPerBlock> az_share_{};   // share of the block's azimuth step
  std::array<std::int32_t, robosense::kChannelsPerBlock> chan_ns_{};  // firing offset in the block
  std::array<std::uint16_t, robosense::kLasers> ring_{};
  std::array<float, robosense::kLasers> cos_vert_{}, sin_vert_{};
  std::array<std::int32_t, robosense::kLasers> horiz_{};
  std::deque<Held> held_;
  std::optional<std::uint32_t> last_counter_;
  double scan_rate_hz_ = 10.0;
  Stats stats_;
};

std::unique_ptr<PacketDecoder> makeRobosenseDecoder(const DecoderConfig& config);
/// "RS-Helios-16P".
std::vector<std::string> robosenseModels();

}  // namespace rigcal::drivers
