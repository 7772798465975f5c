#pragma once
// Hesai decoder: PandarXT16, PandarXT32, PandarXT32M (protocol 6.1), PandarQT128 (QT128C2X, protocol
// 3.2), PandarQT64 (protocol 3.1), Pandar64 and Pandar40P (formats in hesai_packet.hpp).
//
// Axes: Hesai's native frame has y forward and x to the right (x_h = r·cosω·sin(az),
// y_h = r·cosω·cos(az), z_h = r·sinω, az clockwise seen from above). Ours is x forward, y left,
// z up: x = y_h, y = −x_h, z = z_h.
//
// Scan cut: every point reports its own azimuth (block azimuth + the channel's azimuth offset) and
// points leave the decoder sorted by it (see azimuth_order.hpp), so ScanAssembler cuts exactly where
// nebula does: a point belongs to the sweep (C, C + 360°] of its corrected azimuth. The price is a
// short hold-back (QT128 ≈ 20° of rotation, XT ≈ 0.2°): call flush() at end of input.
//
// Returns: dual-return firings keep the last return; a non-last return is dropped when it lies within
// 0.1 m of another return of the same channel (identical returns included), as nebula does.
// Ranges outside both the configured [min, max] and the sensor's own limits are dropped.
// Time: kSensorClock uses the tail date + µs timestamp (UTC, not necessarily GPS-synchronised);
// kHostReceive takes UdpPacket::receive_ns as the time of the packet's last firing. Point times add
// the manual's per-block and per-channel firing offsets (hesai_packet.hpp).
// Loss: gaps in the tail's udp_sequence give lost_before; order_key is the udp_sequence (unwrapped).
#include <array>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/drivers/hesai/azimuth_order.hpp"
#include "rigcal/drivers/hesai/hesai_calibration.hpp"
#include "rigcal/drivers/hesai/hesai_packet.hpp"
#include "rigcal/drivers/packet_decoder.hpp"

namespace rigcal::drivers {

class HesaiDecoder final : public PacketDecoder {
 public:
  struct Stats {
    std::uint64_t crc_errors = 0;       // QT128 packets whose CRC1/CRC2/CRC3 did not match (still decoded)
    std::uint64_t late_firings = 0;     // block azimuths that went backwards a little (reordered packets)
    std::uint64_t discontinuities = 0;  // azimuth jumps that restarted the azimuth ordering
  };

  /// Throws std::runtime_error for an unknown model or a bad calibration file (one line, naming it).
  explicit HesaiDecoder(const DecoderConfig& config);
  HesaiDecoder(const hesai::ModelSpec& spec, const hesai::Calibration& calibration, const DecoderConfig& config);

  void decode(const UdpPacket& packet, DecodedPacket& out) override;
  /// Hands over the points still held for azimuth ordering (end of input); `out` is reset first.
  void flush(DecodedPacket& out) override;
  [[nodiscard]] std::string model() const override { return std::string(spec_.name); }
  [[nodiscard]] double scanRateHz() const override { return scan_rate_hz_; }
  [[nodiscard]] std::size_t maxPointsPerScan() const override { return spec_.max_points_per_scan; }
  [[nodiscard]] const Stats& stats() const { return stats_; }

 private:
  // Firing-time variants: single return, dual with mode_flag bit 0 clear, dual with it set.
  static constexpr int kVariants = 3;
  static int variant(int returns, std::uint8_t mode_flag) { return returns == 1 ? 0 : (mode_flag & 1) ? 2 : 1; }

  // Range and dual-return thresholds in raw distance units, per distance unit (header dis_unit).
  struct RawLimits {
    std::uint8_t unit_mm = 0;  // 0: not computed yet
    double scale = 0;          // metres per raw unit
    std::uint32_t min_raw = 0, max_raw = 0;
    std::uint32_t near_raw = 0, far_raw = 0;
  };
  const RawLimits& rawLimits(std::uint8_t dis_unit_mm);
  template <int kReturns>
  void decodeGroup(const hesai::PacketView& view, int first_block, std::int64_t unwrapped_azimuth, TimeNs t0,
                   const std::int32_t* times, const RawLimits& limits);
  [[nodiscard]] std::uint64_t orderKey(const hesai::PacketView& view, TimeNs t0, std::uint32_t& lost);

  const hesai::ModelSpec& spec_;
  TimeSource time_source_;
  double min_range_m_, max_range_m_;
  int channels_;

  // Per channel, in order of increasing azimuth offset.
  std::vector<std::uint16_t> order_;      // channel index
  std::vector<std::int64_t> shift_;       // bucket of (block azimuth 0 + offset)
  std::vector<float> xy_cos_, xy_sin_, z_sin_;  // cosω·cos(o), cosω·sin(o), sinω
  std::int64_t min_shift_ = 0;
  const float* cos_az_ = nullptr;         // per 0.01° of block azimuth (a shared table)
  const float* sin_az_ = nullptr;
  // times_[variant][block * channels + channel]: firing time relative to t0 (ns).
  std::vector<std::int32_t> times_[kVariants];
  std::int32_t first_firing_ns_[kVariants] = {};
  std::int32_t last_firing_ns_[kVariants] = {};

  std::array<RawLimits, 256> raw_limits_{};
  hesai::AzimuthOrder order_buffer_;
  std::optional<std::int64_t> last_azimuth_;  // unwrapped, 0.01° units
  std::optional<std::uint32_t> last_sequence_;
  std::uint64_t sequence_epoch_ = 0;
  std::array<std::uint8_t, 6> cached_date_{};
  std::int64_t cached_seconds_ = -1;
  double scan_rate_hz_ = 10.0;
  Stats stats_;
};

/// The factory for the generic makeDecoder.
std::unique_ptr<PacketDecoder> makeHesaiDecoder(const DecoderConfig& config);
/// "PandarXT16", "PandarXT32", "PandarQT128", "Pandar40P", "Pandar64", "PandarQT64", "PandarXT32M".
std::vector<std::string> hesaiModels();

}  // namespace rigcal::drivers
