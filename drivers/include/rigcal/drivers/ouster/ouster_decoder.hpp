#pragma once
// Ouster OS0 / OS1 / OS2 lidar decoder, driven by the sensor_info JSON (DecoderConfig::metadata).
//
// Axes. Ouster computes each return in its *lidar* frame (origin on the spin axis at the optical
// centre, +x towards the external connector, column / measurement_id 0 fires along +x and the rotor
// turns clockwise seen from above) and maps it with metadata lidar_to_sensor_transform into its
// *sensor* frame, which is a rotation of 180° about z plus a z offset (36.18 mm on most units):
// x forward (away from the connector), y left, z up. That is already our convention, so the decoder
// outputs Ouster's sensor frame unchanged (applying whatever lidar_to_sensor_transform the file holds),
// in metres. Per pixel (beam u, column v, W columns, range r in mm):
//   θe = 2π(1 − v/W), θa = −beam_azimuth[u], φ = beam_altitude[u]
//   d  = (cos(θe+θa)cosφ, sin(θe+θa)cosφ, sinφ)
//   o  = (cosθe·b, sinθe·b, bz) − d·n,  b, bz = beam_to_lidar_transform (0,3), (2,3)
//        (b = lidar_origin_to_beam_origin_mm on older firmware), n = |(b, bz)|
//   p_sensor = R·(r·d + o) + t, with R, t from lidar_to_sensor_transform; then ×0.001 (mm → m).
// All of it is folded into a per-(column, beam) table at construction: no trig per point.
//
// Sweeps. Every packet carries the sensor's frame_id; DecodedPacket::frame_id is set on every lidar
// packet and the assembler cuts where it changes. A frame starts at measurement_id 0, i.e. behind the
// sensor (−x, the connector side), and runs clockwise. azimuth_deg is still filled per point (atan2(y, x)
// of the return's ray in our frame, in [0, 360)).
//
// Fields. intensity = REFLECTIVITY (present in every profile); ring = beam index (row); dual profiles
// emit the second return with return_index 1. Range 0 (no return) is dropped, as are ranges outside
// [min_range_m, max_range_m] and columns whose status says invalid (outside the column window).
//
// Time. kSensorClock: each point gets its column's timestamp (ns, the sensor's clock: PTP, GPS or time
// since boot, as the sensor is configured). kHostReceive: the packet's receive time stamps its last
// column, earlier columns are spaced by the nominal column period 1/(W·fps).
//
// Loss. Packets are numbered frame_id·(W/columns_per_packet) + measurement_id/columns_per_packet; the
// packets the sensor should have sent (those touching the column window) between the previous packet
// and this one are reported in lost_before. order_key is that number (frame ids unwrapped).
//
// Validation (kMalformed, one line): size ≠ the profile's packet size (48-byte IMU packets sharing the
// port are kIgnored), packet_type ≠ 1, init_id / serial differing from the metadata, CRC-64 mismatch
// (firmware ≥ 3.1), a measurement_id ≥ W.
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rigcal/drivers/ouster/ouster_metadata.hpp"
#include "rigcal/drivers/ouster/ouster_packet_format.hpp"
#include "rigcal/drivers/packet_decoder.hpp"

namespace rigcal::drivers {

/// Builds an Ouster decoder. config.metadata is required; config.model is one of ousterModels()
/// ("Ouster" accepts any unit). Throws std::runtime_error with one line naming the metadata file and
/// the bad field, or the model.
std::unique_ptr<PacketDecoder> makeOusterDecoder(const DecoderConfig& config);

/// "OS0-32", "OS0-64", "OS0-128", "OS1-16", ..., "OS2-128", and "Ouster" (any unit, from the metadata).
std::vector<std::string> ousterModels();

namespace ouster {

class OusterDecoder final : public PacketDecoder {
 public:
  /// Throws std::runtime_error (one line) when the model does not fit the metadata.
  OusterDecoder(const DecoderConfig& config, Metadata metadata);

  void decode(const UdpPacket& packet, DecodedPacket& out) override;
  [[nodiscard]] std::string model() const override { return model_; }
  [[nodiscard]] double scanRateHz() const override { return double(md_.frames_per_second); }
  [[nodiscard]] std::size_t maxPointsPerScan() const override;

  [[nodiscard]] const Metadata& metadata() const { return md_; }
  [[nodiscard]] const PacketFormat& format() const { return format_; }

  /// The precomputed ray of (beam, column): point = d·range_mm + o, metres, our sensor frame.
  struct Ray {
    float dx, dy, dz, ox, oy, oz;
    float azimuth_deg;
    float pad;
  };
  [[nodiscard]] const Ray& ray(int beam, int column) const {
    return rays_[std::size_t(column) * std::size_t(md_.pixels_per_column) + std::size_t(beam)];
  }

 private:
  template <UdpProfile P>
  bool decodeColumns(const std::uint8_t* p, const UdpPacket& packet, DecodedPacket& out);
  void track(std::uint32_t frame_id, int slot, DecodedPacket& out);
  [[nodiscard]] std::uint64_t expectedBefore(std::uint64_t ordinal) const;

  DecoderConfig config_;
  Metadata md_;
  PacketFormat format_;
  std::string model_;
  std::vector<Ray> rays_;          // [column][beam]
  std::vector<int> window_prefix_; // packet slots in window before slot k, k = 0..S
  std::uint32_t min_range_mm_ = 0, max_range_mm_ = 0;
  TimeNs column_period_ns_ = 0;

  bool have_last_ = false;
  std::uint32_t last_frame_id_ = 0;
  std::uint64_t frame_unwrapped_ = 0;
  std::uint64_t last_ordinal_ = 0;
};

}  // namespace ouster
}  // namespace rigcal::drivers
