// Velodyne data packets → points.
//
// Axes. Velodyne's native frame (user manuals) has Y forward (away from the cable), X to the right and
// Z up, with the rotor azimuth α measured clockwise from Y seen from above:
//     X = r·cosω·sin α,  Y = r·cosω·cos α,  Z = r·sinω        (ω = laser elevation)
// Ours is x forward, y left, z up, so x = Y, y = −X, z = Z:
//     x = r·cosω·cos α',  y = −r·cosω·sin α',  z = r·sinω
// with α' = α − rot_correction (the ROS convention, which is also VeloView's). Per-laser beam offsets
// (vert/horiz_offset) enter as in the ROS driver; they are zero in most calibrations.
//
// Time. A data packet carries the time of its first firing as microseconds past the top of the hour;
// every point gets that time plus its firing offset (velodyne_packet.hpp). With the sensor clock the
// hour comes from the receive time (HourResolver); with the host clock the receive time replaces the
// packet's time.
//
// Azimuth. A block carries the azimuth of its first firing; a point's azimuth is interpolated towards
// the next firing sequence's azimuth in proportion to its firing time, rounded to 0.01° (the table
// resolution, and the resolution of the sensor's encoder). The last sequence of a packet reuses the
// step before it. By default the azimuth reported for the scan cut is the block's own azimuth, so a
// block's points (fired within ~0.1 ms) always land in the same sweep, as VeloView splits frames.
//
// Limited field of view (VLP-32C/VLP-16 "FOV" setting): the sensor skips the dead sector but keeps
// filling packets, so one packet can hold the end of one sweep and the start of the next, ~50 ms
// apart at 10 Hz. A block-to-block azimuth jump far beyond what the rotor can turn in one firing
// sequence is recognised as that; the blocks after it are timed by the rotor rate, and the gap is not
// counted as packet loss (also when it falls between two packets, once the dead sector was seen).
#include "rigcal/drivers/velodyne/velodyne_decoder.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <cstdio>
#include <numbers>
#include <stdexcept>

#include "rigcal/drivers/velodyne/velodyne_calibration.hpp"
#include "rigcal/drivers/velodyne/velodyne_packet.hpp"

namespace rigcal::drivers {
namespace velodyne {
namespace {

constexpr TimeNs kNsPerHour = 3600 * kNsPerSec;
constexpr int kAzimuthUnits = 36000;  // hundredths of a degree per turn
constexpr double kMaxRpm = 1200.0;    // the fastest any of these sensors spins

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

TimeNs floorDiv(TimeNs a, TimeNs b) { return a >= 0 ? a / b : -((-a + b - 1) / b); }

// A range limit given as float (DecoderConfig) read back as the decimal it was written as (0.3f → 0.3).
// The float distance is compared with it in double, as nebula compares with its double limits: 150
// counts of 2 mm (0.3000000119 as a float) pass a 0.3 m minimum, 149 do not.
double decimalLimit(float limit) { return std::round(double(limit) * 1e6) / 1e6; }

}  // namespace

TimeNs HourResolver::resolve(std::uint32_t micros_past_hour, TimeNs reference_ns) {
  constexpr TimeNs kLimit = TimeNs(1) << 62;
  reference_ns = std::clamp(reference_ns, -kLimit, kLimit);
  const TimeNs in_hour = TimeNs(micros_past_hour) * kNsPerUs;
  constexpr TimeNs kHalfHour = kNsPerHour / 2;
  if (!anchored_ || std::abs(reference_ns - last_reference_ns_) > 10 * 60 * kNsPerSec) {
    const TimeNs hour = floorDiv(reference_ns, kNsPerHour) * kNsPerHour;
    TimeNs best = hour;
    for (TimeNs candidate : {hour - kNsPerHour, hour + kNsPerHour})
      if (std::abs(candidate + in_hour - reference_ns) < std::abs(best + in_hour - reference_ns))
        best = candidate;
    hour_start_ns_ = best;
    anchored_ = true;
  } else {
    const TimeNs t = hour_start_ns_ + in_hour;
    if (t < last_ns_ - kHalfHour) hour_start_ns_ += kNsPerHour;       // wrapped past the top of the hour
    else if (t > last_ns_ + kHalfHour) hour_start_ns_ -= kNsPerHour;  // a late packet from the last hour
  }
  last_ns_ = hour_start_ns_ + in_hour;
  last_reference_ns_ = reference_ns;
  return last_ns_;
}

namespace {

// cos and sin of every azimuth in 0.01° steps, shared by all decoders.
struct AzimuthTable {
  std::vector<float> cos, sin;
};
const AzimuthTable& azimuthTable() {
  static const AzimuthTable table = [] {
    AzimuthTable t;
    t.cos.resize(kAzimuthUnits);
    t.sin.resize(kAzimuthUnits);
    for (int i = 0; i < kAzimuthUnits; ++i) {
      const double a = i * (std::numbers::pi / 18000.0);
      t.cos[i] = static_cast<float>(std::cos(a));
      t.sin[i] = static_cast<float>(std::sin(a));
    }
    return t;
  }();
  return table;
}

struct LaserTerms {
  float cos_vert, sin_vert;  // elevation
  float cos_rot, sin_rot;    // azimuth correction (subtracted)
  float dist_correction;     // m, added to non-zero distances
  float vert_offset, horiz_offset;
  double rot_hundredths;     // azimuth correction in 0.01° (nebula-style folding)
};

class VelodyneDecoder final : public PacketDecoder {
 public:
  VelodyneDecoder(Model model, const Calibration& calibration, const DecoderConfig& config,
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

  void decode(const UdpPacket& packet, DecodedPacket& out) override;

  [[nodiscard]] std::string model() const override { return info_.name; }
  [[nodiscard]] double scanRateHz() const override { return rate_hz_ > 0 ? rate_hz_ : 10.0; }
  [[nodiscard]] std::size_t maxPointsPerScan() const override {
    // Dual return at the slowest rotor speed (300 rpm): every channel of every block, 5 sweeps/s.
    const double packets_per_s = 1e6 / packetPeriodUs(model_, true);
    return static_cast<std::size_t>(std::ceil(packets_per_s * activeBlocks(model_, true) *
                                              kChannelsPerBlock / 5.0 * 1.02));
  }

 private:
  using Blocks = std::array<int, kBlocksPerPacket>;

  void malformed(DecodedPacket& out, const std::string& why) const {
    out.kind = DecodedPacket::Kind::kMalformed;
    out.error = std::string(info_.name) + " packet: " + why;
  }

  // Time the rotor took to turn `hundredths` beyond one firing sequence: by the measured rotor rate
  // once known (steady over many packets), else by the last step per sequence.
  [[nodiscard]] TimeNs skippedNs(int hundredths, float step) const {
    const double seconds = rate_hz_ > 0 ? hundredths / double(kAzimuthUnits) / rate_hz_ - sequence_us_ * 1e-6
                                        : (hundredths - double(step)) / step * sequence_us_ * 1e-6;
    return std::llround(std::clamp(seconds, 0.0, 1.0) * 1e9);  // a dead sector lasts under a turn
  }

  // nebula's per-channel multiplier of the block's azimuth step (see nebulaAzimuth).
  [[nodiscard]] float nebulaFactor(int bank, int c) const {
    switch (model_) {
      case Model::kVlp16: return float(c % 16) * 2.304f + float(c / 16) * 55.296f;
      case Model::kVls128: {
        const int group = (bank * 32 + c) / 8;
        return (2.665f / 53.3f) * float(group + group / 8);
      }
      default: return float(c);
    }
  }

  // The azimuth index nebula computes for channel c of a block with azimuth az and step diff, with
  // its float arithmetic reproduced operation by operation (the rounding decides ties).
  [[nodiscard]] int nebulaAzimuth(int az, float diff, int bank, int c, double rot_hundredths) const {
    float f = 0;
    switch (model_) {
      case Model::kVlp16: f = float(az) + diff * nebula_factor_[bank][c] / 110.592f; break;
      case Model::kVls128: f = float(az) + diff * nebula_factor_[bank][c]; break;
      default: f = float(az) + diff * 2.304f / 55.296f * nebula_factor_[bank][c]; break;
    }
    float corrected = static_cast<float>(double(f) - rot_hundredths);
    if (corrected < 0.0f) corrected += 36000.0f;
    const long rounded = std::lround(corrected);
    return rounded < 0 ? 0 : static_cast<int>(static_cast<std::uint16_t>(rounded) % kAzimuthUnits);
  }

  template <bool kNebula>
  void emitPoints(const std::uint8_t* p, bool dual, int blocks, const Blocks& bank, const Blocks& azimuth,
                  const std::array<float, kBlocksPerPacket>& step, const std::array<float, kBlocksPerPacket>& nb_diff,
                  const Blocks& nb_azimuth, const std::array<TimeNs, kBlocksPerPacket>& block_ns,
                  DecodedPacket& out) const;

  Model model_;
  const ModelInfo& info_;
  VelodyneOptions options_;
  TimeSource time_source_;
  double min_range_, max_range_;
  const float* cos_az_ = azimuthTable().cos.data();
  const float* sin_az_ = azimuthTable().sin.data();
  std::vector<LaserTerms> lasers_;
  std::int32_t offset_ns_[2][kBlocksPerPacket][4][kChannelsPerBlock];
  float fraction_[4][kChannelsPerBlock];
  float nebula_factor_[4][kChannelsPerBlock];
  double sequence_us_ = 0;
  float max_step_ = 0;  // hundredths of a degree the rotor can turn in one firing sequence

  // Stream state.
  HourResolver hours_;
  bool have_previous_ = false;
  TimeNs expected_next_ns_ = 0;  // sensor time at which the next packet should start
  TimeNs previous_sensor_ns_ = 0;
  int previous_first_azimuth_ = 0, previous_last_azimuth_ = 0;
  float step_ = 0;                     // last azimuth step per firing sequence (0.01°), 0 = unknown
  int dead_from_ = -1, dead_to_ = -1;  // dead sector of a limited field of view, once seen
  double rate_hz_ = 0;
};

template <bool kNebula>
void VelodyneDecoder::emitPoints(const std::uint8_t* p, bool dual, int blocks, const Blocks& bank,
                                 const Blocks& azimuth, const std::array<float, kBlocksPerPacket>& step,
                                 const std::array<float, kBlocksPerPacket>& nb_diff, const Blocks& nb_azimuth,
                                 const std::array<TimeNs, kBlocksPerPacket>& block_ns,
                                 DecodedPacket& out) const {
  const int d = dual ? 1 : 0;
  const float unit = info_.distance_unit_m;
  const bool packet_cut = options_.cut == VelodyneOptions::Cut::kPacket;
  for (int b = 0; b < blocks; ++b) {
    const std::uint8_t* data = channelData(p, b, 0);
    const std::uint8_t* partner = dual && (b & 1) ? channelData(p, b - 1, 0) : nullptr;
    const float az = static_cast<float>(azimuth[b]);
    const float cut_deg = static_cast<float>((packet_cut ? azimuth[0] : azimuth[b]) / 100.0);
    const float s = step[b];
    const int k = bank[b];
    const std::uint8_t return_index = dual ? static_cast<std::uint8_t>(b & 1) : 0;
    const std::int32_t* offsets = offset_ns_[d][b][k];
    for (int c = 0; c < kChannelsPerBlock; ++c, data += 3) {
      const std::uint16_t raw = readU16(data);
      if (raw == 0) continue;
      if (partner && readU16(partner + 3 * c) == raw) continue;  // second return identical to the first
      const int laser = laserOf(model_, k, c);
      const LaserTerms& l = lasers_[laser];
      const float r = static_cast<float>(raw) * unit + l.dist_correction;
      if (!(double(r) > min_range_ && double(r) < max_range_)) continue;
      float cos_a, sin_a;
      if constexpr (kNebula) {
        const int a = nebulaAzimuth(nb_azimuth[b], nb_diff[b], k, c, l.rot_hundredths);
        cos_a = cos_az_[a];
        sin_a = sin_az_[a];
      } else {
        int a = static_cast<int>(az + s * fraction_[k][c] + 0.5f);
        if (a >= kAzimuthUnits) a -= kAzimuthUnits;
        const float ca = cos_az_[a], sa = sin_az_[a];
        cos_a = ca * l.cos_rot + sa * l.sin_rot;  // cos(α − rot_correction)
        sin_a = sa * l.cos_rot - ca * l.sin_rot;  // sin(α − rot_correction)
      }
      const float xy = r * l.cos_vert - l.vert_offset * l.sin_vert;
      Point& pt = out.points.emplace_back();
      pt.x = xy * cos_a + l.horiz_offset * sin_a;
      pt.y = -xy * sin_a + l.horiz_offset * cos_a;
      pt.z = r * l.sin_vert + l.vert_offset * l.cos_vert;
      pt.intensity = data[2];
      pt.ring = static_cast<std::uint16_t>(laser);
      pt.time_ns = block_ns[b] + offsets[c];
      pt.return_index = return_index;
      out.azimuth_deg.push_back(cut_deg);
    }
  }
}

void VelodyneDecoder::decode(const UdpPacket& packet, DecodedPacket& out) {
  out.reset();
  const std::size_t size = packet.payload.size();
  if (size == kPositionPacketSize) {
    out.kind = DecodedPacket::Kind::kIgnored;
    return;
  }
  if (size != kDataPacketSize) {
    malformed(out, "size " + std::to_string(size) + ", expected 1206 (data) or 512 (position)");
    return;
  }
  const std::uint8_t* p = packet.payload.data();

  const std::uint8_t mode = p[kReturnModeOffset];
  bool dual = false;
  if (mode == static_cast<std::uint8_t>(ReturnMode::kDual)) dual = true;
  else if (mode != static_cast<std::uint8_t>(ReturnMode::kStrongest) &&
           mode != static_cast<std::uint8_t>(ReturnMode::kLast) && mode != 0x00) {
    malformed(out, "return mode byte " + hex2(mode) + " unknown");
    return;
  }
  const std::uint8_t product = p[kProductIdOffset];
  if (!productMatches(model_, product)) {
    malformed(out, "product id " + hex2(product) + " (" + productName(product) + ")");
    return;
  }
  const std::uint32_t micros = readU32(p + kTimestampOffset);
  if (micros >= kMicrosPerHour) {
    malformed(out, "timestamp " + std::to_string(micros) + " us is past the hour");
    return;
  }

  const int blocks = activeBlocks(model_, dual);
  Blocks bank{}, azimuth{};
  for (int b = 0; b < blocks; ++b) {
    const std::uint16_t header = blockHeader(p, b);
    int k = 0;
    while (k < 4 && kBankHeaders[k] != header) ++k;
    if (k == 4 || (model_ != Model::kVls128 && k != 0)) {
      malformed(out, "block " + std::to_string(b) + " header " + hex4(header));
      return;
    }
    bank[b] = k;
    azimuth[b] = blockAzimuth(p, b);
    if (azimuth[b] > kAzimuthUnits) {
      malformed(out, "block " + std::to_string(b) + " azimuth " + std::to_string(azimuth[b]) +
                         " beyond 36000");
      return;
    }
    if (azimuth[b] == kAzimuthUnits) azimuth[b] = 0;  // VLP-16 firmware sometimes reports 360.00°
  }

  // Sensor time of the packet; packets lost since the previous one.
  const TimeNs sensor_ns = hours_.resolve(micros, packet.receive_ns);
  const TimeNs base_ns = time_source_ == TimeSource::kSensorClock ? sensor_ns : packet.receive_ns;
  const double period_ns = packetPeriodUs(model_, dual) * 1000.0;
  float known_step = step_;
  if (have_previous_) {
    TimeNs gap = sensor_ns - expected_next_ns_;
    const int boundary = (azimuth[0] - previous_last_azimuth_ + kAzimuthUnits) % kAzimuthUnits;
    if (boundary > 2 * max_step_ && dead_from_ >= 0 && step_ > 0) {
      // The dead sector of a limited field of view, falling between two packets.
      const int tolerance = static_cast<int>(3 * max_step_);
      const auto near = [&](int a, int b) {
        const int diff = std::abs(a - b);
        return std::min(diff, kAzimuthUnits - diff) <= tolerance;
      };
      if (near(previous_last_azimuth_, dead_from_) && near(azimuth[0], dead_to_))
        gap -= skippedNs(boundary, step_);
    }
    if (gap > period_ns / 2 && gap < 3600 * kNsPerSec)
      out.lost_before = static_cast<std::uint32_t>(std::llround(double(gap) / period_ns));
    if (out.lost_before == 0 && boundary <= 2 * max_step_) {
      // Consecutive packets: the step across the boundary is one firing sequence's.
      known_step = static_cast<float>(boundary);
      const TimeNs dt = sensor_ns - previous_sensor_ns_;
      const int advance = (azimuth[0] - previous_first_azimuth_ + kAzimuthUnits) % kAzimuthUnits;
      if (dt > 0 && advance > 0) {
        const double hz = double(advance) / kAzimuthUnits / toSeconds(dt);
        if (hz > 1.0 && hz < 2 * kMaxRpm / 60.0) rate_hz_ = rate_hz_ > 0 ? 0.95 * rate_hz_ + 0.05 * hz : hz;
      }
    }
  }

  // Azimuth step per firing sequence, and the time skipped by a limited field of view.
  std::array<float, kBlocksPerPacket> step{};
  std::array<TimeNs, kBlocksPerPacket> block_ns{};
  TimeNs shift = 0;
  for (int b = 0; b < blocks;) {
    const int next = nextSequenceBlock(model_, dual, b);
    float s = known_step;
    TimeNs jump_ns = 0;
    if (next < blocks) {
      const int raw = (azimuth[next] - azimuth[b] + kAzimuthUnits) % kAzimuthUnits;
      if (raw <= 2 * max_step_) {
        s = static_cast<float>(raw);
        known_step = s;
      } else if (known_step > 0) {
        jump_ns = skippedNs(raw, known_step);
        dead_from_ = azimuth[b];
        dead_to_ = azimuth[next];
      }
    }
    for (int k = b; k < std::min(next, blocks); ++k) {
      step[k] = s;
      block_ns[k] = base_ns + shift;
    }
    shift += jump_ns;
    b = next;
  }
  // Sequences before the first measured step (a first packet that starts with a jump) take the
  // step measured later in the packet.
  for (int b = 0; b < blocks; ++b)
    if (step[b] == 0) step[b] = known_step;

  have_previous_ = true;
  expected_next_ns_ = sensor_ns + static_cast<TimeNs>(period_ns) + shift;
  previous_sensor_ns_ = sensor_ns;
  previous_first_azimuth_ = azimuth[0];
  previous_last_azimuth_ = azimuth[blocks - 1];
  if (known_step > 0) step_ = known_step;

  out.kind = DecodedPacket::Kind::kData;
  out.order_key = static_cast<std::uint64_t>(std::max<TimeNs>(sensor_ns, 0));
  out.packet_time_ns = base_ns + offset_ns_[dual][0][bank[0]][0];

  if (!options_.nebula_azimuth) {
    emitPoints<false>(p, dual, blocks, bank, azimuth, step, {}, {}, block_ns, out);
    return;
  }
  // nebula's pairing: a block takes the azimuth its predecessor looked ahead to (the next block, or
  // the one after in dual mode), the step to the block after that, and no step in the packet's last
  // block (the last-but-one in VLP-16 dual mode).
  std::array<float, kBlocksPerPacket> nb_diff{};
  Blocks nb_azimuth{};
  const int lookahead = dual ? 2 : 1;
  const int no_step_block = model_ == Model::kVlp16 ? 11 - (dual ? 1 : 0) : 11 - (dual ? 4 : 0);
  int next_azimuth = 0;
  float last_diff = 0;
  for (int b = 0; b < blocks; ++b) {
    const int az = b == 0 ? azimuth[0] : next_azimuth;
    if (b < kBlocksPerPacket - lookahead) {
      next_azimuth = blockAzimuth(p, b + lookahead) % kAzimuthUnits;
      last_diff = static_cast<float>((kAzimuthUnits + next_azimuth - az) % kAzimuthUnits);
      nb_diff[b] = last_diff;
    } else {
      nb_diff[b] = b == no_step_block ? 0.0f : last_diff;
    }
    nb_azimuth[b] = az;
  }
  emitPoints<true>(p, dual, blocks, bank, azimuth, step, nb_diff, nb_azimuth, block_ns, out);
}

}  // namespace
}  // namespace velodyne

namespace velodyne {

std::unique_ptr<PacketDecoder> makeDecoder(Model model, const Calibration& calibration, const DecoderConfig& config,
                                           const VelodyneOptions& options) {
  const ModelInfo& info = modelInfo(model);
  if (calibration.lasers.size() != static_cast<std::size_t>(info.lasers))
    throw std::runtime_error(calibration.source + ": lasers: " + std::to_string(calibration.lasers.size()) +
                             " entries, " + info.name + " has " + std::to_string(info.lasers) + " lasers");
  if (!(config.min_range_m >= 0 && config.max_range_m > config.min_range_m))
    throw std::runtime_error(std::string(info.name) + ": min_range/max_range: need 0 <= min < max");
  return std::make_unique<VelodyneDecoder>(model, calibration, config, options);
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
