#include "rigcal/drivers/velodyne/velodyne_packet.hpp"

#include <cctype>
#include <cstdio>

namespace rigcal::drivers::velodyne {
namespace {

// Timing constants from the user manuals (ns).
constexpr std::int64_t kVlp16FiringCycleNs = 55'296, kVlp16FiringNs = 2'304;
constexpr std::int64_t kVlp32FiringCycleNs = 55'296, kVlp32FiringNs = 2'304;
constexpr std::int64_t kHdl32FiringCycleNs = 46'080, kHdl32FiringNs = 1'152;
// HDL-32E manual, Appendix E: firing = timestamp − 542.592 + block·46.08 + DSR·1.152 µs; the timestamp is
// written at the end of the packet, at its last firing (block 11, laser 31). A dual-return packet holds
// 6 firing sequences, so its last firing is 5·46.08 + 31·1.152 µs after its first.
constexpr std::int64_t kHdl32LastFiringNs = 31 * kHdl32FiringNs;
constexpr std::int64_t kVls128SequenceNs = 53'300, kVls128GroupNs = 2'665, kVls128PacketOffsetNs = 8'700;
constexpr double kVlp16FiringCycle = kVlp16FiringCycleNs / 1000.0;
constexpr double kVlp32FiringCycle = kVlp32FiringCycleNs / 1000.0;
constexpr double kHdl32FiringCycle = kHdl32FiringCycleNs / 1000.0;
constexpr double kVls128Sequence = kVls128SequenceNs / 1000.0;

constexpr ModelInfo kModels[] = {
    // VLP-16: a block holds two 16-laser firing sequences.
    {Model::kVlp16, "VLP-16", 16, 0.002f, 0x22, 2 * kVlp16FiringCycle, 1, kVlp16FiringCycle},
    {Model::kVlp32c, "VLP-32C", 32, 0.004f, 0x28, kVlp32FiringCycle, 1, kVlp32FiringCycle},
    {Model::kHdl32e, "HDL-32E", 32, 0.002f, 0x21, kHdl32FiringCycle, 1, kHdl32FiringCycle},
    // VLS-128: four blocks (one per bank of 32 lasers) per firing sequence.
    {Model::kVls128, "VLS-128", 128, 0.004f, 0xA1, kVls128Sequence, 4, kVls128Sequence},
};

std::string normalise(std::string_view s) {
  std::string out;
  for (char c : s)
    if (c != '-' && c != '_' && c != ' ') out += static_cast<char>(std::toupper(static_cast<unsigned char>(c)));
  return out;
}

}  // namespace

const ModelInfo& modelInfo(Model model) { return kModels[static_cast<int>(model)]; }

std::optional<Model> parseModel(std::string_view name) {
  const std::string n = normalise(name);
  for (const ModelInfo& m : kModels)
    if (normalise(m.name) == n) return m.model;
  return std::nullopt;
}

std::vector<std::string> modelNames() {
  std::vector<std::string> out;
  for (const ModelInfo& m : kModels) out.emplace_back(m.name);
  return out;
}

std::string productName(std::uint8_t product_id) {
  switch (product_id) {
    case 0x21: return "HDL-32E";
    case 0x22: return "VLP-16";
    case 0x24: return "VLP-16 Hi-Res";
    case 0x28: return "VLP-32C";
    case 0x31: return "Velarray";
    case 0xA1: return "VLS-128";
    default: {
      char buf[8];
      std::snprintf(buf, sizeof buf, "0x%02X", product_id);
      return buf;
    }
  }
}

bool productMatches(Model model, std::uint8_t product_id) {
  if (product_id == 0x00 || product_id == modelInfo(model).product_id) return true;
  return model == Model::kVlp16 && (product_id == 0x24 || product_id == 0x21);
}

namespace {

// The same in integer nanoseconds, so that ratios of firing times are exact (0.0625, not 0.06249…).
std::int64_t firingOffsetNs(Model model, bool dual, int block, int bank, int channel) {
  const std::int64_t b = dual ? block / 2 : block;
  switch (model) {
    case Model::kVlp16:
      return kVlp16FiringCycleNs * (2 * b + channel / 16) + kVlp16FiringNs * (channel % 16);
    case Model::kVlp32c:
      return kVlp32FiringCycleNs * b + kVlp32FiringNs * (channel / 2);
    case Model::kHdl32e: {
      const std::int64_t last_sequence = dual ? 5 : 11;
      return kHdl32FiringCycleNs * (b - last_sequence) + kHdl32FiringNs * channel - kHdl32LastFiringNs;
    }
    case Model::kVls128: {
      const std::int64_t sequence = dual ? 0 : block / 4;
      const std::int64_t group = (bank * 32 + channel) / 8;
      return kVls128SequenceNs * sequence + kVls128GroupNs * (group + group / 8) - kVls128PacketOffsetNs;
    }
  }
  return 0;
}

}  // namespace

double firingOffsetUs(Model model, bool dual, int block, int bank, int channel) {
  return double(firingOffsetNs(model, dual, block, bank, channel)) / 1000.0;
}

double azimuthFraction(Model model, int bank, int channel) {
  // Firing time after the block's first firing over the time between firing sequences.
  const std::int64_t after = firingOffsetNs(model, false, 0, bank, channel) - firingOffsetNs(model, false, 0, 0, 0);
  switch (model) {
    case Model::kVlp16: return double(after) / double(2 * kVlp16FiringCycleNs);
    case Model::kVlp32c: return double(after) / double(kVlp32FiringCycleNs);
    case Model::kHdl32e: return double(after) / double(kHdl32FiringCycleNs);
    case Model::kVls128: return double(after) / double(kVls128SequenceNs);
  }
  return 0;
}

double packetPeriodUs(Model model, bool dual) {
  const ModelInfo& m = modelInfo(model);
  const double sequences = double(activeBlocks(model, dual)) / m.blocks_per_sequence / (dual ? 2 : 1);
  return sequences * m.block_period_us;
}

}  // namespace rigcal::drivers::velodyne
