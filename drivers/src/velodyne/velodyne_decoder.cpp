// Velodyne data packets → points: the packet walk (size, return mode, product, timestamp, block headers
// and azimuths checked, each failure naming its field), then the packet's timing in the stream
// (velodyne_block_timing.cpp) and its points (velodyne_points.cpp, which also explains the axes and
// azimuths); and the factories.
//
// Time. A data packet carries the time of its first firing as microseconds past the top of the hour;
// every point gets that time plus its firing offset (velodyne_packet.hpp). With the sensor clock the
// hour comes from the receive time (HourResolver); with the host clock the receive time replaces the
// packet's time.
#include "rigcal/drivers/velodyne/velodyne_decoder.hpp"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

#include "velodyne_decoder_impl.hpp"

namespace rigcal::drivers {
namespace velodyne {
namespace detail {
namespace {

std::string hex2(unsigned v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%02X", v & 0xFFu);
  return buf;
}
std::string hex4(unsigned v) {
  char buf[8];
  std::snprintf(buf, sizeof buf, "0x%04X", v & 0xFFFFu);
  return buf;
}

// A range limit given as float (DecoderConfig) read back as the decimal it was written as (0.3f → 0.3).
// The float distance is compared with it in double, as nebula compares with its double limits: 150
// counts of 2 mm (0.3000000119 as a float) pass a 0.3 m minimum, 149 do not.
double decimalLimit(float limit) { return std::round(double(limit) * 1e6) / 1e6; }

}  // namespace

VelodyneDecoder::VelodyneDecoder(Model model, const Calibration& calibration, const DecoderConfig& config,
                                 const VelodyneOptions& options)
    : model_(model), info_(modelInfo(model)), options_(options), time_source_(config.time_source),
      min_range_(decimalLimit(config.min_range_m)), max_range_(decimalLimit(config.max_range_m)) {
  for (const LaserCorrection& l : calibration.lasers)
    lasers_.push_back(LaserTerms{
        static_cast<float>(std::cos(l.vert_correction_rad)),
        static_cast<float>(std::sin(l.vert_correction_rad)),
        static_cast<float>(std::cos(l.rot_correction_rad)),
        static_cast<float>(std::sin(l.rot_correction_rad)), static_cast<float>(l.dist_correction_m),
        static_cast<float>(l.vert_offset_m), static_cast<float>(l.horiz_offset_m),
        double(static_cast<float>(l.rot_correction_rad)) * 180.0 / std::numbers::pi * 100.0});
  for (int dual = 0; dual < 2; ++dual)
    for (int b = 0; b < kBlocksPerPacket; ++b)
      for (int bank = 0; bank < 4; ++bank)
        for (int c = 0; c < kChannelsPerBlock; ++c)
          offset_ns_[dual][b][bank][c] = static_cast<std::int32_t>(
              std::lround(firingOffsetUs(model, dual != 0, b, bank, c) * 1000.0));
  for (int bank = 0; bank < 4; ++bank)
    for (int c = 0; c < kChannelsPerBlock; ++c) {
      fraction_[bank][c] = static_cast<float>(azimuthFraction(model, bank, c));
      nebula_factor_[bank][c] = nebulaFactor(bank, c);
    }
  // A firing sequence is one block, except the VLS-128 (four banks at once).
  sequence_us_ = info_.block_period_us;
  max_step_ = static_cast<float>(kMaxRpm / 60.0 * kAzimuthUnits * sequence_us_ * 1e-6);
}

std::size_t VelodyneDecoder::maxPointsPerScan() const {
  // Dual return at the slowest rotor speed (300 rpm): every channel of every block, 5 sweeps/s.
  const double packets_per_s = 1e6 / packetPeriodUs(model_, true);
  return static_cast<std::size_t>(std::ceil(packets_per_s * activeBlocks(model_, true) *
                                            kChannelsPerBlock / 5.0 * 1.02));
}

void VelodyneDecoder::malformed(DecodedPacket& out, const std::string& why) const {
  out.kind = DecodedPacket::Kind::kMalformed;
  out.error = std::string(info_.name) + " packet: " + why;
}

bool VelodyneDecoder::readBlocks(const UdpPacket& packet, DecodedPacket& out, bool& dual, int& blocks,
                                 Blocks& bank, Blocks& azimuth) const {
  const std::size_t size = packet.payload.size();
  if (size == kPositionPacketSize) {
    out.kind = DecodedPacket::Kind::kIgnored;
    return false;
  }
  if (size != kDataPacketSize) {
    malformed(out, "size " + std::to_string(size) + ", expected 1206 (data) or 512 (position)");
    return false;
  }
  const std::uint8_t* p = packet.payload.data();

  const std::uint8_t mode = p[kReturnModeOffset];
  dual = false;
  if (mode == static_cast<std::uint8_t>(ReturnMode::kDual)) dual = true;
  else if (mode != static_cast<std::uint8_t>(ReturnMode::kStrongest) &&
           mode != static_cast<std::uint8_t>(ReturnMode::kLast) && mode != 0x00) {
    malformed(out, "return mode byte " + hex2(mode) + " unknown");
    return false;
  }
  const std::uint8_t product = p[kProductIdOffset];
  if (!productMatches(model_, product)) {
    malformed(out, "product id " + hex2(product) + " (" + productName(product) + ")");
    return false;
  }
  const std::uint32_t micros = readU32(p + kTimestampOffset);
  if (micros >= kMicrosPerHour) {
    malformed(out, "timestamp " + std::to_string(micros) + " us is past the hour");
    return false;
  }

  blocks = activeBlocks(model_, dual);
  for (int b = 0; b < blocks; ++b) {
    const std::uint16_t header = blockHeader(p, b);
    int k = 0;
    while (k < 4 && kBankHeaders[k] != header) ++k;
    if (k == 4 || (model_ != Model::kVls128 && k != 0)) {
      malformed(out, "block " + std::to_string(b) + " header " + hex4(header));
      return false;
    }
    bank[b] = k;
    azimuth[b] = blockAzimuth(p, b);
    if (azimuth[b] > kAzimuthUnits) {
      malformed(out, "block " + std::to_string(b) + " azimuth " + std::to_string(azimuth[b]) +
                         " beyond 36000");
      return false;
    }
    if (azimuth[b] == kAzimuthUnits) azimuth[b] = 0;  // VLP-16 firmware sometimes reports 360.00°
  }
  return true;
}

void VelodyneDecoder::decode(const UdpPacket& packet, DecodedPacket& out) {
  out.reset();
  bool dual = false;
  int blocks = 0;
  Blocks bank{}, azimuth{};
  if (!readBlocks(packet, out, dual, blocks, bank, azimuth)) return;
  const std::uint8_t* p = packet.payload.data();

  BlockSteps step{};
  BlockTimes block_ns{};
  const PacketTime time =
      timeBlocks(readU32(p + kTimestampOffset), packet.receive_ns, dual, blocks, azimuth, step, block_ns, out);

  out.kind = DecodedPacket::Kind::kData;
  out.order_key = static_cast<std::uint64_t>(std::max<TimeNs>(time.sensor_ns, 0));
  out.packet_time_ns = time.base_ns + offset_ns_[dual][0][bank[0]][0];

  if (options_.nebula_azimuth) emitNebulaPoints(p, dual, blocks, bank, azimuth, step, block_ns, out);
  else emitPoints<false>(p, dual, blocks, bank, azimuth, step, {}, {}, block_ns, out);
}

}  // namespace detail

std::unique_ptr<PacketDecoder> makeDecoder(Model model, const Calibration& calibration, const DecoderConfig& config,
                                           const VelodyneOptions& options) {
  const ModelInfo& info = modelInfo(model);
  if (calibration.lasers.size() != static_cast<std::size_t>(info.lasers))
    throw std::runtime_error(calibration.source + ": lasers: " + std::to_string(calibration.lasers.size()) +
                             " entries, " + info.name + " has " + std::to_string(info.lasers) + " lasers");
  if (!(config.min_range_m >= 0 && config.max_range_m > config.min_range_m))
    throw std::runtime_error(std::string(info.name) + ": min_range/max_range: need 0 <= min < max");
  return std::make_unique<detail::VelodyneDecoder>(model, calibration, config, options);
}

}  // namespace velodyne

std::unique_ptr<PacketDecoder> makeVelodyneDecoder(const DecoderConfig& config, const VelodyneOptions& options) {
  using namespace velodyne;
  const std::optional<Model> model = parseModel(config.model);
  if (!model) {
    std::string known;
    for (const std::string& m : modelNames()) known += (known.empty() ? "" : ", ") + m;
    throw std::runtime_error("unknown Velodyne model '" + config.model + "' (known: " + known + ")");
  }
  if (!config.calibration.empty()) return makeDecoder(*model, loadCalibration(config.calibration, *model), config, options);
  if (auto nominal = nominalCalibration(*model)) return makeDecoder(*model, *nominal, config, options);
  throw std::runtime_error(std::string(modelInfo(*model).name) +
                           ": calibration: a calibration file is required (no nominal table built in)");
}

std::unique_ptr<PacketDecoder> makeVelodyneDecoder(const DecoderConfig& config) {
  return makeVelodyneDecoder(config, VelodyneOptions{});
}

std::vector<std::string> velodyneModels() { return velodyne::modelNames(); }

}  // namespace rigcal::drivers
