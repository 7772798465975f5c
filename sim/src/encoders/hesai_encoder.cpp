// Hesai PandarXT32 point-cloud packets, UDP protocol 6.1, single (strongest) return, 1080 bytes:
//   header 12: 0xEE 0xFF, protocol 6.1, 2 reserved, laser_num 32, block_num 8, first-block-return 1,
//     dis_unit 4 (mm), return_num 1, flags 0x01 (UDP sequence present)
//   8 blocks (one 50 µs firing round each): u16 azimuth (0.01°), 32 × {u16 distance, u8 reflectivity,
//     u8 reserved 0xFF}
//   tail 24: 9 reserved, high-temperature flag 0, return mode 0x37, u16 motor rpm, date (year − 1900,
//     month, day, hour, minute, second, UTC), u32 µs within that second, factory byte 0x42
//   u32 udp_sequence
// The packet time (date + µs) is the manual's t0: block b's round starts at t0 + 5.632 µs − 50 µs·(7 − b).
// Packets are aligned on firing-round numbers: a sensor outage loses whole packets (the udp_sequence
// counts on through it, so the decoder sees the loss), and a partial packet is never sent.
#include <array>
#include <cmath>
#include <cstring>
#include <stdexcept>

#include "encoder_util.hpp"
#include "encoders.hpp"
#include "packet_slots.hpp"
#include "rigcal/core/civil_date.hpp"
#include "rigcal/sim/random.hpp"

namespace rigcal::sim::encoders {
namespace {

constexpr std::size_t kPacketSize = 1080, kHeader = 12, kBlockBytes = 2 + 32 * 4, kTail = kHeader + 8 * kBlockBytes;
constexpr int kBlocks = 8;
constexpr TimeNs kT0AfterFirstRoundNs = 7 * 50'000 - 5'632;
constexpr std::uint8_t kStrongestReturn = 0x37, kFactoryByte = 0x42;

class HesaiXt32Encoder final : public PacketEncoder {
 public:
  HesaiXt32Encoder(const LidarModel& model, std::uint32_t first_udp_sequence)
      : model_(model), first_sequence_(first_udp_sequence), inv_unit_(1.0 / model.distance_unit_m),
        round_ns_(TimeNs(std::ceil(model.firingPeriodNs()))),
        rpm_(std::uint16_t(std::lround(model.rotation_hz * 60.0))) {
    packet_.fill(0);
  }

  void add(const FiringBatch& batch, std::vector<EncodedPacket>& out) override {
    for (std::size_t f = 0; f < batch.size(); ++f) {
      const SimFiring& firing = batch.firings[f];
      const int block = slots_.place(firing.sequence);
      if (block < 0) continue;
      if (block == 0) begin(slots_.packetIndex(), firing);
      write(block, firing, batch.returnsOf(f));
      if (slots_.written()) {
        EncodedPacket& p = out.emplace_back();
        p.payload.assign(packet_.begin(), packet_.end());
        p.send_time_ns = firing.sensor_time_ns + round_ns_;  // after the last round's last firing
      }
    }
  }

  void finish(std::vector<EncodedPacket>& /*out*/) override { slots_.reset(); }

  [[nodiscard]] std::string model() const override { return model_.name; }

 private:
  void begin(std::int64_t index, const SimFiring& first) {
    std::uint8_t* p = packet_.data();
    std::memset(p, 0, kPacketSize);
    const std::uint8_t header[kHeader] = {0xEE, 0xFF, 6, 1, 0, 0, 32, kBlocks, 1, 4, 1, 0x01};
    std::memcpy(p, header, kHeader);
    std::uint8_t* tail = p + kTail;
    tail[10] = kStrongestReturn;
    putU16le(tail + 11, rpm_);
    const TimeNs t0_us = floorDivNs(first.sensor_time_ns + kT0AfterFirstRoundNs + 500, 1000);
    const TimeNs seconds = floorDivNs(t0_us, 1'000'000);
    const CivilDate date = civilFromDays(floorDivNs(seconds, 86'400));
    const TimeNs in_day = floorModNs(seconds, 86'400);
    tail[13] = std::uint8_t(std::clamp<std::int64_t>(date.year - 1900, 0, 255));
    tail[14] = std::uint8_t(date.month);
    tail[15] = std::uint8_t(date.day);
    tail[16] = std::uint8_t(in_day / 3600);
    tail[17] = std::uint8_t(in_day / 60 % 60);
    tail[18] = std::uint8_t(in_day % 60);
    putU32le(tail + 19, std::uint32_t(t0_us - seconds * 1'000'000));
    tail[23] = kFactoryByte;
    putU32le(tail + 24, std::uint32_t(std::uint64_t(first_sequence_) + std::uint64_t(index)));
  }

  void write(int block, const SimFiring& firing, std::span<const LaserReturn> returns) {
    std::uint8_t* b = packet_.data() + kHeader + std::size_t(block) * kBlockBytes;
    putU16le(b, azimuthHundredths(firing.rotor_azimuth_deg));
    std::uint8_t* c = b + 2;
    for (std::size_t ch = 0; ch < 32; ++ch, c += 4) {
      const LaserReturn& r = returns[ch];
      const std::uint32_t counts = rangeCounts(r, inv_unit_, 0xFFFF);
      putU16le(c, counts);
      c[2] = counts ? std::uint8_t(r.intensity) : 0;
      c[3] = 0xFF;  // reserved (what real XT32 units send)
    }
  }

  const LidarModel& model_;
  std::uint32_t first_sequence_;
  double inv_unit_;
  TimeNs round_ns_;
  std::uint16_t rpm_;
  std::array<std::uint8_t, kPacketSize> packet_{};
  PacketSlots slots_{kBlocks};
};

}  // namespace

std::unique_ptr<PacketEncoder> makeHesaiEncoder(const LidarModel& model, const EncoderConfig& config) {
  if (model.name == "Pandar64") return makePandar64Encoder(model, config);
  if (model.name != "PandarXT32") return nullptr;
  if (model.beamCount() != 32 || model.distance_unit_m != 0.004)
    throw std::invalid_argument(model.name + ": the protocol 6.1 encoder needs 32 channels in 4 mm units");
  if (config.dual_return)
    throw std::invalid_argument(model.name + ": dual-return packets are not encoded (single strongest return only)");
  // A real sensor's udp_sequence starts wherever its counter stood: seeded.
  return std::make_unique<HesaiXt32Encoder>(model, std::uint32_t(mix64(config.seed ^ 0x756470ULL)));  // "udp"
}

}  // namespace rigcal::sim::encoders
