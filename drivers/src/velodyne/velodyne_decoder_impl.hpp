#pragma once
// The Velodyne decoder's engine, private to drivers/, one concept per source file:
//   velodyne_decoder.cpp        the packet walk: checks, block headers and azimuths, then timing and points;
//                               the factories
//   velodyne_block_timing.cpp   the stream: hour, lost packets, rotor rate, azimuth step per firing
//                               sequence and the dead sector of a limited field of view
//   velodyne_points.cpp         channel data → points (per-laser terms, azimuth per firing, nebula's variant)
//   velodyne_hour_resolver.cpp  µs past the hour → absolute time
// The file comment of velodyne_decoder.cpp explains the axes, the times and the azimuths.
#include <array>
#include <cstdint>
#include <string>
#include <vector>

#include "rigcal/drivers/velodyne/velodyne_calibration.hpp"
#include "rigcal/drivers/velodyne/velodyne_decoder.hpp"
#include "rigcal/drivers/velodyne/velodyne_packet.hpp"

namespace rigcal::drivers::velodyne::detail {

inline constexpr int kAzimuthUnits = 36000;  // hundredths of a degree per turn
inline constexpr double kMaxRpm = 1200.0;    // the fastest any of these sensors spins

/// cos and sin of every azimuth in 0.01° steps, shared by all decoders.
struct AzimuthTable {
  std::vector<float> cos, sin;
};
const AzimuthTable& azimuthTable();

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
                  const VelodyneOptions& options);

  void decode(const UdpPacket& packet, DecodedPacket& out) override;

  [[nodiscard]] std::string model() const override { return info_.name; }
  [[nodiscard]] double scanRateHz() const override { return rate_hz_ > 0 ? rate_hz_ : 10.0; }
  [[nodiscard]] std::size_t maxPointsPerScan() const override;

 private:
  using Blocks = std::array<int, kBlocksPerPacket>;
  using BlockSteps = std::array<float, kBlocksPerPacket>;
  using BlockTimes = std::array<TimeNs, kBlocksPerPacket>;

  void malformed(DecodedPacket& out, const std::string& why) const;

  /// Checks the packet's size, return mode, product, timestamp and block headers and reads each block's
  /// bank and azimuth; false (out marked malformed or ignored) when the packet yields no points.
  bool readBlocks(const UdpPacket& packet, DecodedPacket& out, bool& dual, int& blocks, Blocks& bank,
                  Blocks& azimuth) const;

  struct PacketTime {
    TimeNs sensor_ns;  // the sensor's clock, the hour resolved from the receive time
    TimeNs base_ns;    // the clock points are stamped with (sensor or receive time)
  };

  /// The packet's place in the stream: sensor time, lost packets before it, the azimuth step of each
  /// firing sequence and each block's time (a limited field of view's dead sector shifts the blocks after
  /// it). Updates the stream state.
  PacketTime timeBlocks(std::uint32_t micros, TimeNs receive_ns, bool dual, int blocks, const Blocks& azimuth,
                    BlockSteps& step, BlockTimes& block_ns, DecodedPacket& out);

  // Time the rotor took to turn `hundredths` beyond one firing sequence: by the measured rotor rate
  // once known (steady over many packets), else by the last step per sequence.
  [[nodiscard]] TimeNs skippedNs(int hundredths, float step) const;

  // nebula's per-channel multiplier of the block's azimuth step (see nebulaAzimuth).
  [[nodiscard]] float nebulaFactor(int bank, int c) const;

  // The azimuth index nebula computes for channel c of a block with azimuth az and step diff, with
  // its float arithmetic reproduced operation by operation (the rounding decides ties).
  [[nodiscard]] int nebulaAzimuth(int az, float diff, int bank, int c, double rot_hundredths) const;

  /// Points of nebula_azimuth mode: nebula's block/step pairing, then emitPoints<true>.
  void emitNebulaPoints(const std::uint8_t* p, bool dual, int blocks, const Blocks& bank, const Blocks& azimuth,
                        const BlockSteps& step, const BlockTimes& block_ns, DecodedPacket& out) const;

  template <bool kNebula>
  void emitPoints(const std::uint8_t* p, bool dual, int blocks, const Blocks& bank, const Blocks& azimuth,
                  const BlockSteps& step, const BlockSteps& nb_diff, const Blocks& nb_azimuth,
                  const BlockTimes& block_ns, DecodedPacket& out) const;

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

}  // namespace rigcal::drivers::velodyne::detail
