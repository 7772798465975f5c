#include "rigcal/drivers/hesai/hesai_firing_times.hpp"

#include <array>

namespace rigcal::drivers::hesai {
namespace {

// Firing time of each channel (index = channel − 1) after its block's start, ns, from the firing-time
// tables of the Pandar40P and Pandar64 user manuals (negative: the laser fires before the block
// time), and of the PandarQT64 manual. The QT64 entry of channel 56 is 129.60 µs: the table as
// reproduced in nebula has 12.96 µs, a dropped digit (its neighbours are 2.06 µs apart).
constexpr std::array<std::int32_t, 40> kPandar40PChannelNs{
    -42220, -28470, -16040, -3620,  -45490, -31740, -47460, -54670, -20620, -33710,
    -40910, -8190,  -20620, -27160, -50730, -8190,  -14740, -36980, -45490, -52700,
    -23890, -31740, -38950, -11470, -18650, -25190, -48760, -6230,  -12770, -35010,
    -21920, -9500,  -43520, -29770, -17350, -4920,  -42220, -28470, -16040, -3620};
constexpr std::array<std::int32_t, 64> kPandar64ChannelNs{
    -23180, -21876, -20572, -19268, -17964, -16660, -11444, -46796, -7532,  -36956, -50732, -54668, -40892,
    -44828, -31052, -34988, -48764, -52700, -38924, -42860, -29084, -33020, -46796, -25148, -36956, -50732,
    -27116, -40892, -44828, -31052, -34988, -48764, -25148, -38924, -42860, -29084, -33020, -52700, -6228,
    -54668, -15356, -27116, -10140, -23180, -4924,  -21876, -14052, -17964, -8836,  -19268, -3620,  -20572,
    -12748, -16660, -7532,  -11444, -6228,  -15356, -10140, -4924,  -3620,  -14052, -8836,  -12748};
constexpr std::array<std::int32_t, 64> kQt64ChannelNs{
    12310,  14370,  16430,  18490,  20540,  22600,  24660,  26710,  29160,  31220,  33280,  35340,  37390,
    39450,  41500,  43560,  46610,  48670,  50730,  52780,  54840,  56900,  58950,  61010,  63450,  65520,
    67580,  69630,  71690,  73740,  75800,  77860,  80900,  82970,  85020,  87080,  89140,  91190,  93250,
    95300,  97750,  99820,  101870, 103930, 105980, 108040, 110100, 112150, 115200, 117260, 119320, 121380,
    123430, 125490, 127540, 129600, 132050, 134110, 136170, 138220, 140280, 142340, 144390, 146450};

// QT128C2X firing sequences (Hesai QT128C2X user manual, Appendix "Absolute Time of Point Cloud
// Data", firetime table): offset of each channel (index = channel − 1) in ns from the start of its
// block; 0 = the channel does not fire in that sequence. 96 channels fire per sequence, in 32
// groups of three 3.168 µs apart (0.600, 1.456, 2.312 µs into the group).
constexpr std::array<std::int32_t, 128> kQtLoop1{
    0,     0,     0,     0,     0,     0,     0,     0,     0,     0,     0,     0,     0,
    0,     0,     0,     0,     0,     0,     0,     0,     0,     0,     0,     0,     0,
    0,     0,     0,     0,     0,     0,     27656, 53000, 2312,  78344, 81512, 5480,  56168,
    30824, 33992, 59336, 8648,  84680, 87848, 11816, 62504, 37160, 40328, 65672, 14984, 91016,
    94184, 18152, 68840, 43496, 46664, 72008, 21320, 97352, 100520, 24488, 75176, 49832, 1456,
    77488, 26800, 52144, 55312, 29968, 80656, 4624,  7792,  83824, 33136, 58480, 61648, 36304,
    86992, 10960, 14128, 90160, 39472, 64816, 67984, 42640, 93328, 17296, 20464, 96496, 45808,
    71152, 74320, 48976, 99664, 23632, 25944, 51288, 600,   76632, 79800, 3768,  54456, 29112,
    32280, 57624, 6936,  82968, 86136, 10104, 60792, 35448, 38616, 63960, 13272, 89304, 92472,
    16440, 67128, 41784, 44952, 70296, 19608, 95640, 98808, 22776, 73464, 48120};
constexpr std::array<std::int32_t, 128> kQtLoop2{
    2312,  78344, 27656, 53000, 56168, 30824, 81512, 5480,  8648,  84680, 33992, 59336, 62504,
    37160, 87848, 11816, 14984, 91016, 40328, 65672, 68840, 43496, 94184, 18152, 21320, 97352,
    46664, 72008, 75176, 49832, 100520, 24488, 0,    0,     0,     0,     0,     0,     0,
    0,     0,     0,     0,     0,     0,     0,     0,     0,     0,     0,     0,     0,
    0,     0,     0,     0,     0,     0,     0,     0,     0,     0,     0,     0,     600,
    76632, 25944, 51288, 54456, 29112, 79800, 3768,  6936,  82968, 32280, 57624, 60792, 35448,
    86136, 10104, 13272, 89304, 38616, 63960, 67128, 41784, 92472, 16440, 19608, 95640, 44952,
    70296, 73464, 48120, 98808, 22776, 26800, 52144, 1456,  77488, 80656, 4624,  55312, 29968,
    33136, 58480, 7792,  83824, 86992, 10960, 61648, 36304, 39472, 64816, 14128, 90160, 93328,
    17296, 67984, 42640, 45808, 71152, 20464, 96496, 99664, 23632, 74320, 48976};

}  // namespace

std::int32_t qt128LoopOffsetNs(int loop, int channel) {
  if (channel < 0 || channel >= 128) return 0;
  return loop == 1 ? kQtLoop1[channel] : kQtLoop2[channel];
}

std::int64_t firingOffsetNs(Model model, int returns, int block, int channel, std::uint8_t mode_flag) {
  returns = returns == 2 ? 2 : 1;
  switch (model) {
    case Model::kXT16:
    case Model::kXT32:
    case Model::kXT32M: {
      // Firing rounds are 50 µs apart; t0 is the trigger of the last round (block 8, or 7 & 8).
      const int blocks = model == Model::kXT32M ? 6 : 8;
      const int rounds_after = (blocks / returns - 1) - block / returns;
      const std::int64_t block_start = 5'632 - 50'000 * std::int64_t(rounds_after);
      if (model == Model::kXT32M) return block_start + 368 + 2'888 * (channel % 16);
      const std::int64_t step = model == Model::kXT32 ? 1'512 : 3'024;
      return block_start + 368 + step * channel;
    }
    case Model::kPandar40P:
    case Model::kPandar64: {
      // Firing rounds are 55.56 µs apart; t0 is the time of the last round.
      const bool p40 = model == Model::kPandar40P;
      const int rounds_after = ((p40 ? 10 : 6) / returns - 1) - block / returns;
      const std::int64_t block_start = (p40 ? -28'580 : -42'580) - 55'560 * std::int64_t(rounds_after);
      if (channel < 0 || channel >= (p40 ? 40 : 64)) return block_start;
      return block_start + (p40 ? kPandar40PChannelNs[channel] : kPandar64ChannelNs[channel]);
    }
    case Model::kQT64: {
      // Firing rounds are 166.67 µs apart; t0 is the time of the packet's first round.
      const std::int64_t block_start = 25'710 + 500'000 * std::int64_t(block / returns) / 3;
      if (channel < 0 || channel >= 64) return block_start;
      return block_start + kQt64ChannelNs[channel];
    }
    case Model::kQT128: {
      // One firing round is 111.11 µs (900 rounds per turn at 10 Hz).
      const std::int64_t block_start = returns == 1 && block == 0 ? 9'000 - 111'110 : 9'000;
      const int loop = returns == 1 ? block + 1 : ((mode_flag & 0x01) ? 1 : 2);
      return block_start + qt128LoopOffsetNs(loop, channel);
    }
  }
  return 0;
}

}  // namespace rigcal::drivers::hesai
