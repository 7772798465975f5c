// Velodyne data packets (VLP-16, VLP-32C, VLS-128), single (strongest) return: 1206 bytes of twelve
// 100-byte blocks {u16 0xEEFF (VLS-128 banks 0xEEFF/0xDDFF/0xCCFF/0xBBFF), u16 azimuth in 0.01°,
// 32 × {u16 distance, u8 reflectivity}}, u32 µs past the hour, return mode 0x37, product id.
//
// A packet holds a fixed number of consecutive firing sequences (VLP-16: 24, two per block; VLP-32C:
// 12; VLS-128: 3 of four banks). Packets are aligned on sequence numbers, so a sensor that falls
// silent (an outage) loses whole packets, as a real one would; a packet the capture starts or ends
// in the middle of is not emitted.
#include <array>
#include <cstring>
#include <stdexcept>

#include "encoder_util.hpp"
#include "encoders.hpp"
#include "packet_slots.hpp"

namespace rigcal::sim::encoders {
namespace {

constexpr std::size_t kPacketSize = 1206;
constexpr std::size_t kBlockSize = 100;
constexpr std::uint16_t kBankHeaders[4] = {0xEEFF, 0xDDFF, 0xCCFF, 0xBBFF};
constexpr std::uint8_t kStrongestReturn = 0x37;
constexpr TimeNs kMicrosPerHour = 3'600'000'000LL;

struct Layout {
  std::uint8_t product_id;
  int sequences_per_block;  // VLP-16 packs two 16-laser sequences into one block
  int blocks_per_sequence;  // VLS-128 spreads one sequence over four banks
  TimeNs timestamp_after_first_firing_ns;  // VLS-128 stamps 8.7 µs after its first firing
};

class VelodyneEncoder final : public PacketEncoder {
 public:
  VelodyneEncoder(const LidarModel& model, const Layout& layout)
      : model_(model), layout_(layout), beams_(model.beamCount()),
        per_packet_(12 / layout.blocks_per_sequence * layout.sequences_per_block),
        inv_unit_(1.0 / model.distance_unit_m), period_ns_(TimeNs(std::ceil(model.firingPeriodNs()))) {
    packet_.fill(0);
  }

  void add(const FiringBatch& batch, std::vector<EncodedPacket>& out) override {
    for (std::size_t f = 0; f < batch.size(); ++f) {
      const SimFiring& firing = batch.firings[f];
      const int slot = slots_.place(firing.sequence);
      if (slot < 0) continue;
      if (slot == 0) begin(firing);
      write(slot, firing, batch.returnsOf(f));
      if (slots_.written()) {
        emit(firing, out);
      }
    }
  }

  void finish(std::vector<EncodedPacket>& /*out*/) override {
    slots_.reset();  // a Velodyne packet always has twelve full blocks: a partial one is never sent
  }

  [[nodiscard]] std::string model() const override { return model_.name; }

 private:
  void begin(const SimFiring& first) {
    std::memset(packet_.data(), 0, 1200);
    const TimeNs stamp = first.sensor_time_ns + layout_.timestamp_after_first_firing_ns;
    const TimeNs micros = floorDivNs(stamp + 500, 1000);  // nearest microsecond
    putU32le(packet_.data() + 1200, std::uint32_t(floorModNs(micros, kMicrosPerHour)));
    packet_[1204] = kStrongestReturn;
    packet_[1205] = layout_.product_id;
  }

  void write(int slot, const SimFiring& firing, std::span<const LaserReturn> returns) {
    const int block0 = slot / layout_.sequences_per_block * layout_.blocks_per_sequence;
    const int channel0 = slot % layout_.sequences_per_block * int(beams_);
    if (channel0 == 0) {
      const std::uint32_t azimuth = azimuthHundredths(firing.rotor_azimuth_deg);
      for (int k = 0; k < layout_.blocks_per_sequence; ++k) {
        std::uint8_t* block = packet_.data() + (block0 + k) * kBlockSize;
        putU16le(block, kBankHeaders[k]);
        putU16le(block + 2, azimuth);
      }
    }
    for (std::size_t laser = 0; laser < beams_; ++laser) {
      const LaserReturn& r = returns[laser];
      std::uint8_t* channel =
          packet_.data() + (block0 + int(laser / 32)) * kBlockSize + 4 + 3 * (channel0 + int(laser % 32));
      const std::uint32_t counts = rangeCounts(r, inv_unit_, 0xFFFF);
      putU16le(channel, counts);
      channel[2] = counts ? std::uint8_t(r.intensity) : 0;
    }
  }

  void emit(const SimFiring& last, std::vector<EncodedPacket>& out) {
    EncodedPacket& p = out.emplace_back();
    p.payload.assign(packet_.begin(), packet_.end());
    p.send_time_ns = last.sensor_time_ns + period_ns_;  // after the last sequence's last firing
  }

  const LidarModel& model_;
  Layout layout_;
  std::size_t beams_;
  int per_packet_;
  double inv_unit_;
  TimeNs period_ns_;
  std::array<std::uint8_t, kPacketSize> packet_{};
  PacketSlots slots_{per_packet_};
};

}  // namespace

std::unique_ptr<PacketEncoder> makeVelodyneEncoder(const LidarModel& model, const EncoderConfig& config) {
  Layout layout{};
  std::size_t lasers = 0;
  if (model.name == "VLP-16") {
    layout = {0x22, 2, 1, 0};
    lasers = 16;
  } else if (model.name == "VLP-32C") {
    layout = {0x28, 1, 1, 0};
    lasers = 32;
  } else if (model.name == "VLS-128") {
    layout = {0xA1, 1, 4, 8'700};
    lasers = 128;
  } else {
    return nullptr;
  }
  if (model.beamCount() != lasers)
    throw std::invalid_argument(model.name + ": " + std::to_string(model.beamCount()) + " beams, the packet carries " +
                                std::to_string(lasers));
  if (config.dual_return)
    throw std::invalid_argument(model.name + ": dual-return packets are not encoded (single strongest return only)");
  return std::make_unique<VelodyneEncoder>(model, layout);
}

}  // namespace rigcal::sim::encoders
