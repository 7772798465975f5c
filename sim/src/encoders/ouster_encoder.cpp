// Ouster lidar packets, profile RNG19_RFL8_SIG16_NIR16 (default) or LEGACY (firmware 2.x eUDP), 16 columns per packet:
//   packet header 32: u16 packet_type = 1, u16 frame_id, u24 init_id, u40 serial, alert/countdown
//     fields (0: no alerts, no thermal or shot limiting)
//   16 columns: u64 timestamp (ns, the sensor's PTP clock), u16 measurement_id, u16 status (1 = valid),
//     then one 12-byte pixel per beam row (staggered, as the sensor sends them): u32 whose low 19 bits
//     are the range in mm, u8 reflectivity, u8 0, u16 signal, u16 near_ir, u16 0
//   packet footer 32: zero but for the last 8 bytes, which firmware 2.3–3.0 fills with the placeholder
//     DE C0 00 00 EF BE AD DE where 3.1 and later put a CRC-64 (the metadata says v2.5.0)
// LEGACY profile (firmware ≤ 2.x default): no packet header or footer; each column is a 16-byte header
//   (u64 timestamp, u16 measurement_id, u16 frame_id, u32 encoder count = 88 ticks per column of 1024)
//   then 12-byte pixels (u32 whose low 20 bits are the range in mm, u16 reflectivity, u16 signal,
//   u16 near_ir, u16 0) and a u32 status (0xFFFFFFFF valid, 0 not measured).
// Packets hold measurement ids 16k..16k+15 of one frame. A packet the capture only partly covers
// (start, end, a sensor outage) is sent with its missing columns marked invalid, as the sensor marks
// columns outside its column window.
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <vector>

#include "encoder_util.hpp"
#include "encoders.hpp"
#include "ouster_identity.hpp"

namespace rigcal::sim::encoders {
namespace {

constexpr int kColumnsPerPacket = 16;
constexpr std::size_t kPixel = 12;
constexpr std::uint32_t kEncoderTicksPerTurn = 90'112;

struct Layout {
  bool legacy;
  std::size_t packet_header, column_header, column_footer, packet_footer;
  std::uint32_t max_range_mm;
};
constexpr Layout kRng19{false, 32, 12, 0, 32, (1u << 19) - 1};
constexpr Layout kLegacy{true, 0, 16, 4, 0, (1u << 20) - 1};

class OusterEncoder final : public PacketEncoder {
 public:
  OusterEncoder(const LidarModel& model, const OusterIdentity& id, const Layout& layout)
      : model_(model), id_(id), layout_(layout), rows_(model.beamCount()),
        column_size_(layout.column_header + rows_ * kPixel + layout.column_footer),
        packet_size_(layout.packet_header + kColumnsPerPacket * column_size_ + layout.packet_footer),
        inv_unit_mm_(1.0 / 0.001), column_ns_(TimeNs(std::ceil(model.firingPeriodNs()))) {
    packet_.assign(packet_size_, 0);
  }

  void add(const FiringBatch& batch, std::vector<EncodedPacket>& out) override {
    for (std::size_t f = 0; f < batch.size(); ++f) {
      const SimFiring& firing = batch.firings[f];
      const std::int64_t index = floorDivNs(firing.sequence, kColumnsPerPacket);
      if (open_ && index != index_) emit(out);
      if (!open_) begin(index, firing);
      write(firing, batch.returnsOf(f));
    }
  }

  void finish(std::vector<EncodedPacket>& out) override {
    if (open_) emit(out);
  }

  [[nodiscard]] std::string model() const override { return model_.name; }

 private:
  void begin(std::int64_t index, const SimFiring& firing) {
    open_ = true;
    index_ = index;
    std::memset(packet_.data(), 0, packet_size_);
    // Every column starts as "not measured" but names its measurement id (the decoder places the
    // packet by its first column's id) and, in LEGACY, the frame id.
    const int first_id = int(floorModNs(firing.sequence, model_.columns_per_frame)) / kColumnsPerPacket * kColumnsPerPacket;
    const std::uint32_t frame_id = std::uint32_t(firing.frame & 0xffff);
    for (int c = 0; c < kColumnsPerPacket; ++c) {
      putU16le(column(c) + 8, std::uint32_t(first_id + c));
      if (layout_.legacy) {
        putU16le(column(c) + 10, frame_id);
        putU32le(column(c) + 12, std::uint32_t(first_id + c) * (kEncoderTicksPerTurn / std::uint32_t(model_.columns_per_frame)));
      }
    }
    if (layout_.legacy) return;
    std::uint8_t* h = packet_.data();
    putU16le(h, 1);  // lidar data
    putU16le(h + 2, frame_id);
    putU32le(h + 4, id_.init_id);  // u24; byte 7 is overwritten by the serial
    for (int i = 0; i < 5; ++i) h[7 + i] = std::uint8_t(id_.serial >> (8 * i));
    static constexpr std::uint8_t kFooterPlaceholder[8] = {0xDE, 0xC0, 0x00, 0x00, 0xEF, 0xBE, 0xAD, 0xDE};
    std::memcpy(packet_.data() + packet_size_ - 8, kFooterPlaceholder, 8);
  }

  [[nodiscard]] std::uint8_t* column(int c) {
    return packet_.data() + layout_.packet_header + std::size_t(c) * column_size_;
  }

  void write(const SimFiring& firing, std::span<const LaserReturn> returns) {
    const int c = int(floorModNs(firing.sequence, kColumnsPerPacket));
    std::uint8_t* col = column(c);
    putU64le(col, std::uint64_t(firing.sensor_time_ns));
    putU16le(col + 8, std::uint32_t(firing.column));
    if (layout_.legacy) putU32le(col + column_size_ - 4, 0xFFFFFFFFu);  // valid
    else putU16le(col + 10, 1);
    std::uint8_t* px = col + layout_.column_header;
    for (std::size_t row = 0; row < rows_; ++row, px += kPixel) {
      const LaserReturn& r = returns[row];
      const std::uint32_t mm = rangeCounts(r, inv_unit_mm_, layout_.max_range_mm);
      putU32le(px, mm);
      px[4] = mm ? std::uint8_t(r.intensity) : 0;  // u8 (RNG19) or the low byte of a u16 (LEGACY)
      // Signal photons grow with the reflectivity; near-IR is a dim, row-dependent ambient level.
      putU16le(px + 6, mm ? 8u + 4u * std::uint32_t(r.intensity) : 0u);
      putU16le(px + 8, 40u + std::uint32_t((firing.column * 7 + int(row) * 13) & 63));
    }
    last_time_ns_ = firing.sensor_time_ns;
  }

  void emit(std::vector<EncodedPacket>& out) {
    EncodedPacket& p = out.emplace_back();
    p.payload = packet_;
    p.send_time_ns = last_time_ns_ + column_ns_;  // after its last column is measured
    open_ = false;
  }

  const LidarModel& model_;
  OusterIdentity id_;
  Layout layout_;
  std::size_t rows_, column_size_, packet_size_;
  double inv_unit_mm_;
  TimeNs column_ns_;
  std::vector<std::uint8_t> packet_;
  bool open_ = false;
  std::int64_t index_ = 0;
  TimeNs last_time_ns_ = 0;
};

}  // namespace

std::unique_ptr<PacketEncoder> makeOusterEncoder(const LidarModel& model, const EncoderConfig& config) {
  if (model.name != "OS1-64" && model.name != "OS1-128") return nullptr;
  if (model.columns_per_frame % kColumnsPerPacket != 0 || model.distance_unit_m != 0.001)
    throw std::invalid_argument(model.name + ": the Ouster encoder needs millimetre ranges and whole packets per frame");
  if (config.dual_return)
    throw std::invalid_argument(model.name + ": dual-return packets are not encoded (single return only)");
  return std::make_unique<OusterEncoder>(model, ousterIdentity(config.sensor_name, config.lidar_port),
                                         config.ouster_legacy ? kLegacy : kRng19);
}

}  // namespace rigcal::sim::encoders
