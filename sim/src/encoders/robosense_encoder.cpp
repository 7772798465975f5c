// RoboSense RS-Helios-16P, single (strongest) return. Two packet kinds, both 1248 bytes, big-endian
// (drivers/include/rigcal/drivers/robosense/robosense_packet.hpp has the layouts the decoder reads):
//  MSOP, to the data port: header 42 (55 AA 05 5A, u32 packet counter @12, u48 UTC seconds + u32 µs
//    @20 = the first block's time), 12 blocks of {FF EE, u16 azimuth 0.01°, 32 × {u16 distance in
//    2.5 mm, u8 intensity}}, tail 6. One block per firing sequence; channel slot c is model beam c.
//  DIFOP, to EncoderConfig::info_port: id A5 FF 00 5A 11 11 55 55, rpm @8, FOV 0..360° @32, return mode
//    0x04 (strongest) @300, vertical angles @468 and horizontal offsets @564 as {u8 sign, u16 0.01°} per
//    laser. Sent before the first MSOP packet (the decoder holds data until it has one) and once a
//    second after, as the sensor does.
// Packets are aligned on firing-sequence numbers, as the Hesai encoders': an outage loses whole packets.
#include <array>
#include <cmath>
#include <cstring>
#include <optional>
#include <stdexcept>

#include "encoder_util.hpp"
#include "encoders.hpp"
#include "packet_slots.hpp"
#include "rigcal/sim/random.hpp"

namespace rigcal::sim::encoders {
namespace {

constexpr int kBlocks = 12, kSlots = 32, kLasers = 16;
constexpr std::size_t kPacketSize = 1248, kHeader = 42, kBlockBytes = 100;
constexpr TimeNs kDifopPeriodNs = 1'000'000'000;

void putU16be(std::uint8_t* p, std::uint32_t v) {
  p[0] = std::uint8_t(v >> 8);
  p[1] = std::uint8_t(v);
}
void putU32be(std::uint8_t* p, std::uint32_t v) {
  putU16be(p, v >> 16);
  putU16be(p + 2, v);
}
void putAngle(std::uint8_t* p, double deg) {
  const long v = std::lround(deg * 100.0);
  p[0] = v < 0 ? 1 : 0;
  putU16be(p + 1, std::uint32_t(std::labs(v)));
}

class RobosenseEncoder final : public PacketEncoder {
 public:
  RobosenseEncoder(const LidarModel& model, std::uint16_t info_port, std::uint32_t first_counter)
      : model_(model), info_port_(info_port), first_counter_(first_counter), inv_unit_(1.0 / model.distance_unit_m) {
    writeDifop();
  }

  void add(const FiringBatch& batch, std::vector<EncodedPacket>& out) override {
    for (std::size_t f = 0; f < batch.size(); ++f) {
      const SimFiring& firing = batch.firings[f];
      const int block = slots_.place(firing.sequence);
      if (block < 0) continue;
      if (block == 0) {
        if (!next_difop_ns_ || firing.sensor_time_ns >= *next_difop_ns_) {
          EncodedPacket& d = out.emplace_back();
          d.payload.assign(difop_.begin(), difop_.end());
          d.send_time_ns = firing.sensor_time_ns;
          d.destination_port = info_port_;
          next_difop_ns_ = firing.sensor_time_ns + kDifopPeriodNs;
        }
        begin(slots_.packetIndex(), firing);
      }
      write(block, firing, batch.returnsOf(f));
      if (slots_.written()) {
        EncodedPacket& p = out.emplace_back();
        p.payload.assign(msop_.begin(), msop_.end());
        p.send_time_ns = firing.sensor_time_ns + model_.beams.back().time_offset_ns + 1'000;  // after its last slot
      }
    }
  }

  void finish(std::vector<EncodedPacket>& /*out*/) override { slots_.reset(); }

  [[nodiscard]] std::string model() const override { return model_.name; }

 private:
  void writeDifop() {
    std::uint8_t* p = difop_.data();
    const std::uint8_t id[8] = {0xA5, 0xFF, 0x00, 0x5A, 0x11, 0x11, 0x55, 0x55};
    std::memcpy(p, id, sizeof id);
    putU16be(p + 8, std::uint32_t(std::lround(model_.rotation_hz * 60.0)));
    putU16be(p + 32, 0);
    putU16be(p + 34, 36000);
    p[300] = 0x04;  // strongest return
    for (int l = 0; l < kLasers; ++l) {
      putAngle(p + 468 + 3 * std::size_t(l), model_.beams[std::size_t(l)].elevation_deg);
      putAngle(p + 564 + 3 * std::size_t(l), detail::helios16pHorizontalOffsetDeg(model_, std::size_t(l)));
    }
    p[kPacketSize - 2] = 0x0F;  // tail
    p[kPacketSize - 1] = 0xF0;
  }

  void begin(std::int64_t index, const SimFiring& first) {
    std::uint8_t* p = msop_.data();
    std::memset(p, 0, kPacketSize);
    const std::uint8_t id[4] = {0x55, 0xAA, 0x05, 0x5A};
    std::memcpy(p, id, sizeof id);
    putU32be(p + 12, std::uint32_t(std::uint64_t(first_counter_) + std::uint64_t(index)));
    const TimeNs t_us = floorDivNs(first.sensor_time_ns + 500, 1000);
    const TimeNs seconds = floorDivNs(t_us, 1'000'000);
    putU16be(p + 20, std::uint32_t(std::uint64_t(seconds) >> 32));
    putU32be(p + 22, std::uint32_t(seconds));
    putU32be(p + 26, std::uint32_t(t_us - seconds * 1'000'000));
    p[kPacketSize - 1] = 0xFF;  // tail, as the recorded unit sends it
  }

  void write(int block, const SimFiring& firing, std::span<const LaserReturn> returns) {
    std::uint8_t* b = msop_.data() + kHeader + std::size_t(block) * kBlockBytes;
    b[0] = 0xFF;
    b[1] = 0xEE;
    putU16be(b + 2, azimuthHundredths(firing.rotor_azimuth_deg));
    std::uint8_t* c = b + 4;
    for (std::size_t slot = 0; slot < kSlots; ++slot, c += 3) {
      const LaserReturn& r = returns[slot];
      const std::uint32_t counts = rangeCounts(r, inv_unit_, 0xFFFF);
      putU16be(c, counts);
      c[2] = counts ? std::uint8_t(r.intensity) : 0;
    }
  }

  const LidarModel& model_;
  std::uint16_t info_port_;
  std::uint32_t first_counter_;
  double inv_unit_;
  std::array<std::uint8_t, kPacketSize> msop_{}, difop_{};
  std::optional<TimeNs> next_difop_ns_;
  PacketSlots slots_{kBlocks};
};

}  // namespace

std::unique_ptr<PacketEncoder> makeRobosenseEncoder(const LidarModel& model, const EncoderConfig& config) {
  if (model.name != "RS-Helios-16P") return nullptr;
  if (model.beamCount() != kSlots || model.distance_unit_m != 0.0025)
    throw std::invalid_argument(model.name + ": the Helios-16P encoder needs 32 channel slots in 2.5 mm units");
  if (config.dual_return)
    throw std::invalid_argument(model.name + ": dual-return packets are not encoded (single strongest return only)");
  if (config.info_port == 0) throw std::invalid_argument(model.name + ": the encoder needs the DIFOP port (info_port)");
  return std::make_unique<RobosenseEncoder>(model, config.info_port, std::uint32_t(mix64(config.seed ^ 0x6d736f70ULL)));  // "msop"
}

}  // namespace rigcal::sim::encoders
