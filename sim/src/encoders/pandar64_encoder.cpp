// Hesai Pandar64 point-cloud packets, single (strongest) return, 1198 bytes (hesai_packet.hpp has the
// layout the decoder reads):
//   header 8: 0xEE 0xFF, laser_num 64, block_num 6, reserved, dis_unit 4 (mm), 2 reserved
//   6 blocks (one 55.56 µs firing round each): u16 azimuth (0.01°), 64 × {u16 distance, u8 reflectivity}
//   tail 22: 5 reserved, high-temperature flag 0, 2 reserved, u16 motor rpm, u32 µs within the second,
//     return mode 0x37, factory byte 0x42, date (year − 1900 as the recorded unit sends it, month, day,
//     hour, minute, second, UTC)
//   u32 udp_sequence
// The packet time (date + µs) is the time of block 6: block b's lasers fire 42.58 µs + 55.56 µs·(5 − b)
// before it, each by its firing-time table entry earlier still (LidarModel::beams carry that table
// shifted so the earliest laser fires at the round's start).
// Packets are aligned on firing-round numbers, as the XT32 encoder's: an outage loses whole packets.
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

constexpr int kBlocks = 6, kChannels = 64;
constexpr std::size_t kHeader = 8, kBlockBytes = 2 + kChannels * 3, kTail = kHeader + kBlocks * kBlockBytes;
constexpr std::size_t kPacketSize = kTail + 22 + 4;
// From the start of the first round to the packet time: the earliest laser fires at the round's start,
// which is kPandar64EarliestNs before that laser's table time, itself 42.58 µs + 5 rounds before t0.
constexpr TimeNs kT0AfterFirstRoundNs = detail::kPandar64EarliestNs + 42'580 + 5 * detail::kPandar64RoundNs;
constexpr std::uint8_t kStrongestReturn = 0x37, kFactoryByte = 0x42;

class Pandar64Encoder final : public PacketEncoder {
 public:
  Pandar64Encoder(const LidarModel& model, std::uint32_t first_udp_sequence)
      : model_(model), first_sequence_(first_udp_sequence), inv_unit_(1.0 / model.distance_unit_m),
        round_ns_(TimeNs(std::ceil(model.firingPeriodNs()))),
        rpm_(std::uint16_t(std::lround(model.rotation_hz * 60.0))) {}

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
    const std::uint8_t header[kHeader] = {0xEE, 0xFF, kChannels, kBlocks, 0, 4, 0, 0};
    std::memcpy(p, header, kHeader);
    std::uint8_t* tail = p + kTail;
    putU16le(tail + 8, rpm_);
    const TimeNs t0_us = floorDivNs(first.sensor_time_ns + kT0AfterFirstRoundNs + 500, 1000);
    const TimeNs seconds = floorDivNs(t0_us, 1'000'000);
    putU32le(tail + 10, std::uint32_t(t0_us - seconds * 1'000'000));
    tail[14] = kStrongestReturn;
    tail[15] = kFactoryByte;
    const CivilDate date = civilFromDays(floorDivNs(seconds, 86'400));
    const TimeNs in_day = floorModNs(seconds, 86'400);
    tail[16] = std::uint8_t(std::clamp<std::int64_t>(date.year - 1900, 0, 255));
    tail[17] = std::uint8_t(date.month);
    tail[18] = std::uint8_t(date.day);
    tail[19] = std::uint8_t(in_day / 3600);
    tail[20] = std::uint8_t(in_day / 60 % 60);
    tail[21] = std::uint8_t(in_day % 60);
    putU32le(tail + 22, std::uint32_t(std::uint64_t(first_sequence_) + std::uint64_t(index)));
  }

  void write(int block, const SimFiring& firing, std::span<const LaserReturn> returns) {
    std::uint8_t* b = packet_.data() + kHeader + std::size_t(block) * kBlockBytes;
    putU16le(b, azimuthHundredths(firing.rotor_azimuth_deg));
    std::uint8_t* c = b + 2;
    for (std::size_t ch = 0; ch < kChannels; ++ch, c += 3) {
      const LaserReturn& r = returns[ch];
      const std::uint32_t counts = rangeCounts(r, inv_unit_, 0xFFFF);
      putU16le(c, counts);
      c[2] = counts ? std::uint8_t(r.intensity) : 0;
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

std::unique_ptr<PacketEncoder> makePandar64Encoder(const LidarModel& model, const EncoderConfig& config) {
  if (model.beamCount() != kChannels || model.distance_unit_m != 0.004)
    throw std::invalid_argument(model.name + ": the Pandar64 encoder needs 64 channels in 4 mm units");
  if (config.dual_return)
    throw std::invalid_argument(model.name + ": dual-return packets are not encoded (single strongest return only)");
  return std::make_unique<Pandar64Encoder>(model, std::uint32_t(mix64(config.seed ^ 0x756470ULL)));  // "udp"
}

}  // namespace rigcal::sim::encoders
