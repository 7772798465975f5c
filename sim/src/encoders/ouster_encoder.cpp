// Ouster lidar packets, profile RNG19_RFL8_SIG16_NIR16 (firmware 2.x eUDP), 16 columns per packet:
//   packet header 32: u16 packet_type = 1, u16 frame_id, u24 init_id, u40 serial, alert/countdown
//     fields (0: no alerts, no thermal or shot limiting)
//   16 columns: u64 timestamp (ns, the sensor's PTP clock), u16 measurement_id, u16 status (1 = valid),
//     then one 12-byte pixel per beam row (staggered, as the sensor sends them): u32 whose low 19 bits
//     are the range in mm, u8 reflectivity, u8 0, u16 signal, u16 near_ir, u16 0
//   packet footer 32: zero but for the last 8 bytes, which firmware 2.3–3.0 fills with the placeholder
//     DE C0 00 00 EF BE AD DE where 3.1 and later put a CRC-64 (the metadata says v2.5.0)
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
constexpr std::size_t kPacketHeader = 32, kColumnHeader = 12, kPixel = 12, kPacketFooter = 32;
constexpr std::uint32_t kMaxRangeMm = (1u << 19) - 1;

class OusterEncoder final : public PacketEncoder {
 public:
  OusterEncoder(const LidarModel& model, const OusterIdentity& id)
      : model_(model), id_(id), rows_(model.beamCount()), column_size_(kColumnHeader + rows_ * kPixel),
        packet_size_(kPacketHeader + kColumnsPerPacket * column_size_ + kPacketFooter),
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
    std::uint8_t* h = packet_.data();
    putU16le(h, 1);  // lidar data
    putU16le(h + 2, std::uint32_t(firing.frame & 0xffff));
    putU32le(h + 4, id_.init_id);  // u24; byte 7 is overwritten by the serial
    for (int i = 0; i < 5; ++i) h[7 + i] = std::uint8_t(id_.serial >> (8 * i));
    // Every column starts as "not measured" but names its measurement id (the decoder places the
    // packet by its first column's id).
    const int first_id = int(floorModNs(firing.sequence, model_.columns_per_frame)) / kColumnsPerPacket * kColumnsPerPacket;
    for (int c = 0; c < kColumnsPerPacket; ++c) putU16le(column(c) + 8, std::uint32_t(first_id + c));
    static constexpr std::uint8_t kFooterPlaceholder[8] = {0xDE, 0xC0, 0x00, 0x00, 0xEF, 0xBE, 0xAD, 0xDE};
    std::memcpy(packet_.data() + packet_size_ - 8, kFooterPlaceholder, 8);
  }

  [[nodiscard]] std::uint8_t* column(int c) { return packet_.data() + kPacketHeader + std::size_t(c) * column_size_; }

  void write(const SimFiring& firing, std::span<const LaserReturn> returns) {
    const int c = int(floorModNs(firing.sequence, kColumnsPerPacket));
    std::uint8_t* col = column(c);
    putU64le(col, std::uint64_t(firing.sensor_time_ns));
    putU16le(col + 8, std::uint32_t(firing.column));
    putU16le(col + 10, 1);  // valid
    std::uint8_t* px = col + kColumnHeader;
    for (std::size_t row = 0; row < rows_; ++row, px += kPixel) {
      const LaserReturn& r = returns[row];
      const std::uint32_t mm = rangeCounts(r, inv_unit_mm_, kMaxRangeMm);
      putU32le(px, mm);
      px[4] = mm ? std::uint8_t(r.intensity) : 0;
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
    throw std::invalid_argument(model.name + ": the RNG19 encoder needs millimetre ranges and whole packets per frame");
  if (config.dual_return)
    throw std::invalid_argument(model.name + ": dual-return packets are not encoded (single return only)");
  return std::make_unique<OusterEncoder>(model, ousterIdentity(config.sensor_name, config.lidar_port));
}

}  // namespace rigcal::sim::encoders
