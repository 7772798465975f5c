#pragma once
// Velodyne packet format: the 1206-byte data packet (12 blocks × 100 bytes, a 4-byte timestamp and two
// factory bytes), the 512-byte position packet, the models we decode and their firing timing.
//
// Data packet (little-endian):
//   block b (b = 0..11) at offset 100·b: u16 header (0xEEFF; VLS-128 banks 0xEEFF/0xDDFF/0xCCFF/0xBBFF),
//     u16 azimuth (hundredths of a degree, 0..35999), 32 channels × {u16 distance, u8 reflectivity}
//   offset 1200: u32 timestamp, microseconds past the top of the hour
//   offset 1204: return mode (0x37 strongest, 0x38 last, 0x39 dual)
//   offset 1205: product id (0x21 HDL-32E, 0x22 VLP-16, 0x24 VLP-16 Hi-Res, 0x28 VLP-32C, 0xA1 VLS-128)
#include <array>
#include <cstddef>
#include <cstdint>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace rigcal::drivers::velodyne {

inline constexpr std::size_t kDataPacketSize = 1206;
inline constexpr std::size_t kPositionPacketSize = 512;
inline constexpr int kBlocksPerPacket = 12;
inline constexpr int kBlockSize = 100;
inline constexpr int kChannelsPerBlock = 32;
inline constexpr int kPointsPerPacket = kBlocksPerPacket * kChannelsPerBlock;
inline constexpr std::size_t kTimestampOffset = 1200;
inline constexpr std::size_t kReturnModeOffset = 1204;
inline constexpr std::size_t kProductIdOffset = 1205;
inline constexpr std::uint32_t kMicrosPerHour = 3'600'000'000u;

inline constexpr std::uint16_t kBankHeaders[4] = {0xEEFF, 0xDDFF, 0xCCFF, 0xBBFF};

enum class Model : std::uint8_t { kVlp16, kVlp32c, kHdl32e, kVls128 };

enum class ReturnMode : std::uint8_t { kStrongest = 0x37, kLast = 0x38, kDual = 0x39 };

struct ModelInfo {
  Model model;
  const char* name;             // canonical name, as DecoderConfig::model spells it
  int lasers;                   // lasers in the calibration table
  float distance_unit_m;        // one count of the 2-byte distance
  std::uint8_t product_id;      // factory byte 1205
  double block_period_us;       // time between consecutive blocks' first firings (single return)
  int blocks_per_sequence;      // blocks fired at the same instant (VLS-128: 4 banks)
  double firing_cycle_us;       // one firing sequence (for the scan-rate and loss estimates)
};

const ModelInfo& modelInfo(Model model);
/// "VLP-16", "VLP-32C", "HDL-32E", "VLS-128" (case-insensitive, '-' optional); nullopt otherwise.
std::optional<Model> parseModel(std::string_view name);
/// Canonical model names, in the order above.
std::vector<std::string> modelNames();
/// Human name of a product id byte ("VLP-32C"), or "0x.." when unknown.
std::string productName(std::uint8_t product_id);
/// Whether a data packet carrying `product_id` may be decoded as `model`. 0x00 (unset) is accepted;
/// VLP-16 also accepts 0x24 (Hi-Res, same layout) and 0x21 (reported by early VLP-16 firmware).
bool productMatches(Model model, std::uint8_t product_id);

// --- raw field access (callers guarantee a kDataPacketSize buffer) ---
inline std::uint16_t readU16(const std::uint8_t* p) {
  return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
}
inline std::uint32_t readU32(const std::uint8_t* p) {
  return static_cast<std::uint32_t>(p[0]) | (static_cast<std::uint32_t>(p[1]) << 8) |
         (static_cast<std::uint32_t>(p[2]) << 16) | (static_cast<std::uint32_t>(p[3]) << 24);
}
inline std::uint16_t blockHeader(const std::uint8_t* packet, int block) {
  return readU16(packet + block * kBlockSize);
}
inline std::uint16_t blockAzimuth(const std::uint8_t* packet, int block) {
  return readU16(packet + block * kBlockSize + 2);
}
inline const std::uint8_t* channelData(const std::uint8_t* packet, int block, int channel) {
  return packet + block * kBlockSize + 4 + 3 * channel;
}

/// Laser index (row of the calibration table) of channel `channel` of a block with bank `bank`.
inline int laserOf(Model model, int bank, int channel) {
  switch (model) {
    case Model::kVlp16: return channel & 15;
    case Model::kVls128: return bank * 32 + channel;
    default: return channel;
  }
}

/// Time of the firing of (block, channel) relative to the packet timestamp, in microseconds
/// (Velodyne user manuals):
///   VLP-16   55.296·(2·b' + ⌊c/16⌋) + 2.304·(c mod 16)
///   HDL-32E  46.08·b' + 1.152·c − T, one laser at a time; the stamp is the packet's last firing (manual,
///            Appendix E: −542.592 + 46.08·b + 1.152·DSR), so T = 542.592 (single) or 266.112 (dual)
///   VLP-32C  55.296·b' + 2.304·⌊c/2⌋
///   VLS-128  53.3·s + 2.665·(g + ⌊g/8⌋) − 8.7, firing group g = ⌊laser/8⌋, sequence s = ⌊b/4⌋
/// where b' = b in single-return mode and ⌊b/2⌋ in dual mode (both blocks of a pair hold the same
/// firing); a VLS-128 dual packet holds one sequence (s = 0). `bank` matters for the VLS-128 only.
double firingOffsetUs(Model model, bool dual, int block, int bank, int channel);

/// Fraction of the azimuth step between one firing sequence's block and the next at which
/// channel `channel` (of bank `bank`) fires: the per-point azimuth is az + step · fraction.
double azimuthFraction(Model model, int bank, int channel);

/// Nominal time between two data packets (µs).
double packetPeriodUs(Model model, bool dual);

/// Blocks carrying data in one packet: 12, or 8 for a VLS-128 dual-return packet.
inline int activeBlocks(Model model, bool dual) { return model == Model::kVls128 && dual ? 8 : 12; }

/// Block whose azimuth follows `block`'s firing sequence: the next block, the next pair (dual), or the
/// next group of four banks (VLS-128). Returns ≥ activeBlocks when the sequence is the packet's last.
inline int nextSequenceBlock(Model model, bool dual, int block) {
  if (model == Model::kVls128) return dual ? 12 : (block / 4 + 1) * 4;
  return dual ? (block / 2 + 1) * 2 : block + 1;
}

}  // namespace rigcal::drivers::velodyne
