// A data packet's channel data → points: range, per-laser corrections, azimuth per firing, time.
//
// Axes. Velodyne's native frame (user manuals) has Y forward (away from the cable), X to the right and
// Z up, with the rotor azimuth α measured clockwise from Y seen from above:
//     X = r·cosω·sin α,  Y = r·cosω·cos α,  Z = r·sinω        (ω = laser elevation)
// Ours is x forward, y left, z up, so x = Y, y = −X, z = Z:
//     x = r·cosω·cos α',  y = −r·cosω·sin α',  z = r·sinω
// with α' = α − rot_correction (the ROS convention, which is also VeloView's). Per-laser beam offsets
// (vert/horiz_offset) enter as in the ROS driver; they are zero in most calibrations.
//
// Azimuth. A block carries the azimuth of its first firing; a point's azimuth is interpolated towards
// the next firing sequence's azimuth in proportion to its firing time, rounded to 0.01° (the table
// resolution, and the resolution of the sensor's encoder). The last sequence of a packet reuses the
// step before it. By default the azimuth reported for the scan cut is the block's own azimuth, so a
// block's points (fired within ~0.1 ms) always land in the same sweep, as VeloView splits frames.
#include <cmath>
#include <numbers>

#include "velodyne_decoder_impl.hpp"

namespace rigcal::drivers::velodyne::detail {

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

float VelodyneDecoder::nebulaFactor(int bank, int c) const {
  switch (model_) {
    case Model::kVlp16: return float(c % 16) * 2.304f + float(c / 16) * 55.296f;
    case Model::kVls128: {
      const int group = (bank * 32 + c) / 8;
      return (2.665f / 53.3f) * float(group + group / 8);
    }
    default: return float(c);
  }
}

int VelodyneDecoder::nebulaAzimuth(int az, float diff, int bank, int c, double rot_hundredths) const {
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
void VelodyneDecoder::emitPoints(const std::uint8_t* p, bool dual, int blocks, const Blocks& bank,
                                 const Blocks& azimuth, const BlockSteps& step, const BlockSteps& nb_diff,
                                 const Blocks& nb_azimuth, const BlockTimes& block_ns, DecodedPacket& out) const {
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

template void VelodyneDecoder::emitPoints<false>(const std::uint8_t*, bool, int, const Blocks&, const Blocks&,
                                                 const BlockSteps&, const BlockSteps&, const Blocks&,
                                                 const BlockTimes&, DecodedPacket&) const;

void VelodyneDecoder::emitNebulaPoints(const std::uint8_t* p, bool dual, int blocks, const Blocks& bank,
                                       const Blocks& azimuth, const BlockSteps& step, const BlockTimes& block_ns,
                                       DecodedPacket& out) const {
  // nebula's pairing: a block takes the azimuth its predecessor looked ahead to (the next block, or
  // the one after in dual mode), the step to the block after that, and no step in the packet's last
  // block (the last-but-one in VLP-16 dual mode).
  BlockSteps nb_diff{};
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

}  // namespace rigcal::drivers::velodyne::detail
