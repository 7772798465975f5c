#include "rigcal/drivers/hesai/hesai_packet.hpp"

#include <algorithm>

#if defined(__x86_64__)
#include <immintrin.h>
#endif

#include "rigcal/core/civil_date.hpp"

namespace rigcal::drivers::hesai {
namespace {

// Range limits of the newer models are the ones nebula applies (the references were made with them).
// max_points_per_scan: slowest rotation (10 Hz for the 40P, 64 and QT64; 5 Hz for the XT32M), dual
// return, every channel.
constexpr std::array<ModelSpec, 7> kModels{{
    {Model::kXT16, "PandarXT16", 6, 1, 16, 8, 0.05f, 120.0f, 128'000, Protocol::kXt61, 1900},
    {Model::kXT32, "PandarXT32", 6, 1, 32, 8, 0.05f, 120.0f, 256'000, Protocol::kXt61, 1900},
    {Model::kQT128, "PandarQT128", 3, 2, 128, 2, 0.05f, 50.0f, 172'800, Protocol::kQt32, 1900},
    {Model::kPandar40P, "Pandar40P", 0, 0, 40, 10, 0.3f, 200.0f, 144'000, Protocol::kPandar40P, 2000},
    {Model::kPandar64, "Pandar64", 0, 0, 64, 6, 0.3f, 200.0f, 230'400, Protocol::kPandar64, 2000},
    {Model::kQT64, "PandarQT64", 3, 1, 64, 4, 0.1f, 60.0f, 76'800, Protocol::kQt31, 1900},
    {Model::kXT32M, "PandarXT32M", 6, 1, 32, 6, 0.5f, 300.0f, 256'000, Protocol::kXt61, 1900},
}};

constexpr std::size_t kHeaderBytes = 12;
constexpr std::size_t kXtTailBytes = 24;
constexpr std::size_t kQtTailBytes = 26;
constexpr std::size_t kQtSafetyBytes = 17;
constexpr std::size_t kQtSignatureBytes = 32;

// Where the common fields sit in each protocol's tail (XT: protocol 6.1, QT128: 3.2): the fields are
// the same, the QT tail carries two more bytes (mode flag, reserved) before them.
struct TailLayout {
  std::size_t return_mode, motor_rpm, date, timestamp_us;
};
constexpr TailLayout kXtTail{10, 11, 13, 19};
constexpr TailLayout kQtTail{12, 13, 15, 21};
// The older formats put the µs timestamp before the return mode and the date last.
constexpr std::size_t kQt64TailBytes = 24;
constexpr TailLayout kQt64Tail{16, 10, 18, 12};
constexpr std::size_t kLegacyTailBytes = 22;  // Pandar64 and Pandar40P
constexpr TailLayout kLegacyTail{14, 8, 16, 10};
constexpr std::size_t kPandar64HeaderBytes = 8;

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

std::uint16_t u16(const std::uint8_t* p) { return static_cast<std::uint16_t>(p[0] | (p[1] << 8)); }
std::uint32_t u32(const std::uint8_t* p) {
  return std::uint32_t(p[0]) | (std::uint32_t(p[1]) << 8) | (std::uint32_t(p[2]) << 16) |
         (std::uint32_t(p[3]) << 24);
}

std::string hex(unsigned v, int digits) {
  static constexpr char kDigits[] = "0123456789ABCDEF";
  std::string s = "0x";
  for (int i = digits - 1; i >= 0; --i) s += kDigits[(v >> (4 * i)) & 0xF];
  return s;
}

std::string fail(const ModelSpec& spec, const std::string& what) {
  return std::string(spec.name) + " packet: " + what;
}

// Slicing-by-16 tables for the non-reflected CRC-32/MPEG-2: t[s][i] is the CRC register after
// byte i followed by s zero bytes.
struct CrcTables {
  std::array<std::array<std::uint32_t, 256>, 16> t{};
  CrcTables() {
    for (std::uint32_t i = 0; i < 256; ++i) {
      std::uint32_t c = i << 24;
      for (int k = 0; k < 8; ++k) c = (c & 0x80000000u) ? (c << 1) ^ 0x04C11DB7u : (c << 1);
      t[0][i] = c;
    }
    for (std::uint32_t i = 0; i < 256; ++i)
      for (int s = 1; s < 16; ++s) t[s][i] = (t[s - 1][i] << 8) ^ t[0][t[s - 1][i] >> 24];
  }
};
const CrcTables& crcTables() {
  static const CrcTables tables;
  return tables;
}

void readTail(const std::uint8_t* tail, const TailLayout& at, PacketView& v) {
  v.return_mode = tail[at.return_mode];
  v.motor_rpm = u16(tail + at.motor_rpm);
  std::copy_n(tail + at.date, 6, v.date.begin());
  v.timestamp_us = u32(tail + at.timestamp_us);
}

}  // namespace

std::span<const ModelSpec> allModels() { return kModels; }

const ModelSpec* findModel(std::string_view name) {
  for (const ModelSpec& m : kModels)
    if (m.name == name) return &m;
  return nullptr;
}

int returnsPerFiring(std::uint8_t mode) {
  switch (mode) {
    case return_mode::kFirst:
    case return_mode::kSecond:
    case return_mode::kStrongest:
    case return_mode::kLast:
      return 1;
    case return_mode::kLastStrongest:
    case return_mode::kFirstSecond:
    case return_mode::kFirstLast:
    case return_mode::kFirstStrongest:
    case return_mode::kStrongestSecondStrongest:
      return 2;
    default:
      return 0;
  }
}

bool isGpsPacket(std::span<const std::uint8_t> payload) {
  return payload.size() == 512 && payload[0] == 0xFF && payload[1] == 0xEE;
}

namespace {

std::uint32_t crcTable(std::uint32_t c, const std::uint8_t* p, std::size_t n) {
  const auto& t = crcTables().t;
  while (n >= 16) {
    const std::uint32_t a = c ^ ((std::uint32_t(p[0]) << 24) | (std::uint32_t(p[1]) << 16) |
                                 (std::uint32_t(p[2]) << 8) | std::uint32_t(p[3]));
    c = t[15][a >> 24] ^ t[14][(a >> 16) & 0xFF] ^ t[13][(a >> 8) & 0xFF] ^ t[12][a & 0xFF] ^ t[11][p[4]] ^
        t[10][p[5]] ^ t[9][p[6]] ^ t[8][p[7]] ^ t[7][p[8]] ^ t[6][p[9]] ^ t[5][p[10]] ^ t[4][p[11]] ^
        t[3][p[12]] ^ t[2][p[13]] ^ t[1][p[14]] ^ t[0][p[15]];
    p += 16;
    n -= 16;
  }
  while (n--) c = (c << 8) ^ t[0][((c >> 24) ^ *p++) & 0xFF];
  return c;
}

#if defined(__x86_64__)
// Carry-less multiplication folding (the method of Intel's "Fast CRC Computation for Generic
// Polynomials Using PCLMULQDQ", non-reflected form): 16 bytes at a time are folded into a 128-bit
// remainder with x^192 mod P and x^128 mod P; the last remainder and the tail bytes go through the
// table. Used when the CPU has PCLMULQDQ and SSSE3.
std::uint64_t xPowModP(int n) {
  std::uint64_t r = 1;
  for (int i = 0; i < n; ++i) {
    r <<= 1;
    if (r & (std::uint64_t(1) << 32)) r ^= 0x104C11DB7ull;
  }
  return r;
}

__attribute__((target("pclmul,ssse3"))) std::uint32_t crcFold(const std::uint8_t* p, std::size_t n) {
  static const __m128i k = _mm_set_epi64x(static_cast<long long>(xPowModP(192)), static_cast<long long>(xPowModP(128)));
  const __m128i swap = _mm_set_epi8(0, 1, 2, 3, 4, 5, 6, 7, 8, 9, 10, 11, 12, 13, 14, 15);
  __m128i x = _mm_shuffle_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)), swap);
  x = _mm_xor_si128(x, _mm_set_epi32(-1, 0, 0, 0));  // the initial register 0xFFFFFFFF
  p += 16;
  n -= 16;
  while (n >= 16) {
    const __m128i next = _mm_shuffle_epi8(_mm_loadu_si128(reinterpret_cast<const __m128i*>(p)), swap);
    x = _mm_xor_si128(_mm_xor_si128(_mm_clmulepi64_si128(x, k, 0x11), _mm_clmulepi64_si128(x, k, 0x00)), next);
    p += 16;
    n -= 16;
  }
  alignas(16) std::uint8_t rest[16];
  _mm_store_si128(reinterpret_cast<__m128i*>(rest), _mm_shuffle_epi8(x, swap));
  return crcTable(crcTable(0, rest, 16), p, n);
}

bool haveClmul() {
  static const bool have = __builtin_cpu_supports("pclmul") && __builtin_cpu_supports("ssse3");
  return have;
}
#endif

}  // namespace

std::uint32_t crc32Mpeg2(std::span<const std::uint8_t> bytes) {
#if defined(__x86_64__)
  if (bytes.size() >= 64 && haveClmul()) return crcFold(bytes.data(), bytes.size());
#endif
  return crcTable(0xFFFFFFFFu, bytes.data(), bytes.size());
}

std::optional<std::int64_t> utcSeconds(const std::array<std::uint8_t, 6>& d, int year_base) {
  const unsigned month = d[1], day = d[2], hour = d[3], minute = d[4], second = d[5];
  if (month < 1 || month > 12 || day < 1 || day > 31 || hour > 23 || minute > 59 || second > 60)
    return std::nullopt;
  const std::int64_t days = daysFromCivil(year_base + std::int64_t(d[0]), month, day);
  return days * 86400 + hour * 3600 + minute * 60 + second;
}

namespace {
const TailLayout& tailLayout(const ModelSpec& spec) {
  switch (spec.protocol) {
    case Protocol::kXt61: return kXtTail;
    case Protocol::kQt32: return kQtTail;
    case Protocol::kQt31: return kQt64Tail;
    case Protocol::kPandar64:
    case Protocol::kPandar40P: return kLegacyTail;
  }
  return kXtTail;
}
}  // namespace

int yearBase(const ModelSpec& spec, std::uint8_t year_byte) {
  return spec.year_base == 2000 && year_byte >= 100 ? 1900 : spec.year_base;
}

std::size_t tailDateOffset(const ModelSpec& spec) { return tailLayout(spec).date; }
std::size_t tailTimestampOffset(const ModelSpec& spec) { return tailLayout(spec).timestamp_us; }

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

namespace {

// Protocols 6.1 (XT) and 3.2 (QT128): everything after the 12-byte header (already checked).
std::string parseXtOrQt128(const ModelSpec& spec, std::span<const std::uint8_t> payload, PacketView& v) {
  const std::size_t size = payload.size();
  const std::uint8_t* p = payload.data();
  const std::uint8_t flags = p[11];

  const std::size_t body_bytes = std::size_t(spec.blocks) * v.blockBytes();
  const std::size_t body_end = kHeaderBytes + body_bytes;

  const std::uint8_t* tail = nullptr;
  if (spec.protocol_major == 6) {
    if (!(flags & 0x01)) return fail(spec, "flags " + hex(flags, 2) + " without the UDP sequence bit");
    const std::size_t expected = body_end + kXtTailBytes + 4;
    if (size != expected)
      return fail(spec, "size " + std::to_string(size) + ", expected " + std::to_string(expected));
    tail = p + body_end;
    readTail(tail, kXtTail, v);
    v.udp_sequence = u32(tail + kXtTailBytes);
    v.mode_flag = 0;
    v.has_crc = false;
    v.crc_ok = true;
    v.tail = tail;
    v.tail_crc_bytes = 0;
  } else {
    if (flags & 0x02) return fail(spec, "flags " + hex(flags, 2) + " announce IMU fields (not supported)");
    if (flags & 0x40)
      return fail(spec, "flags " + hex(flags, 2) + " announce channel customization (not supported)");
    const bool has_safety = flags & 0x04, has_sequence = flags & 0x01, has_signature = flags & 0x08;
    const std::size_t tail_at = body_end + 4 + (has_safety ? kQtSafetyBytes : 0);
    const std::size_t expected =
        tail_at + kQtTailBytes + (has_sequence ? 4 : 0) + 4 + (has_signature ? kQtSignatureBytes : 0);
    if (size != expected)
      return fail(spec, "size " + std::to_string(size) + ", expected " + std::to_string(expected) +
                            " for flags " + hex(flags, 2));
    tail = p + tail_at;
    v.mode_flag = tail[5];
    readTail(tail, kQtTail, v);
    const std::size_t tail_end = kQtTailBytes + (has_sequence ? 4 : 0);
    v.udp_sequence.reset();
    if (has_sequence) v.udp_sequence = u32(tail + kQtTailBytes);
    v.has_crc = true;
    v.tail = tail;
    v.tail_crc_bytes = tail_end;
    bool ok = crc32Mpeg2({v.body, body_bytes}) == u32(p + body_end);
    if (has_safety) {
      const std::uint8_t* fs = p + body_end + 4;
      ok = ok && crc32Mpeg2({fs + 1, 12}) == u32(fs + 13);
    }
    ok = ok && crc32Mpeg2({tail, tail_end}) == u32(tail + tail_end);
    v.crc_ok = ok;
  }

  return {};
}

// The Pandar40P and Pandar64 formats: no protocol version, a fixed 4 mm unit (Pandar40P) or the
// header's, 3-byte units, the return count from the tail only, an optional trailing udp_sequence.
std::string parseLegacy(const ModelSpec& spec, std::span<const std::uint8_t> payload, PacketView& v) {
  const std::size_t size = payload.size();
  const std::uint8_t* p = payload.data();
  const bool p40 = spec.protocol == Protocol::kPandar40P;
  const std::size_t header = p40 ? 0 : kPandar64HeaderBytes;
  v.channels = spec.channels;
  v.blocks = spec.blocks;
  v.block_prefix = p40 ? 4 : 2;
  v.unit_bytes = 3;
  const std::size_t body_end = header + std::size_t(spec.blocks) * v.blockBytes();
  const std::size_t bare = body_end + kLegacyTailBytes;
  if (size != bare && size != bare + 4)
    return fail(spec, "size " + std::to_string(size) + ", expected " + std::to_string(bare) + " or " +
                          std::to_string(bare + 4) + " (with udp_sequence)");
  if (p40) {
    v.dis_unit_mm = 4;
  } else {
    if (p[0] != 0xEE || p[1] != 0xFF)
      return fail(spec, "start of packet " + hex(unsigned(p[0]) << 8 | p[1], 4) + ", expected 0xEEFF");
    if (p[2] != spec.channels)
      return fail(spec, "laser_num " + std::to_string(p[2]) + ", expected " + std::to_string(spec.channels));
    if (p[3] != spec.blocks)
      return fail(spec, "block_num " + std::to_string(p[3]) + ", expected " + std::to_string(spec.blocks));
    if (p[5] == 0) return fail(spec, "dis_unit 0");
    v.dis_unit_mm = p[5];
  }
  v.body = p + header;
  if (p40)
    for (int b = 0; b < spec.blocks; ++b) {
      const std::uint8_t* block = v.block(b);
      if (block[0] != 0xFF || block[1] != 0xEE)
        return fail(spec, "block " + std::to_string(b + 1) + " starts " + hex(unsigned(block[0]) << 8 | block[1], 4) +
                              ", expected 0xFFEE");
    }
  v.tail = p + body_end;
  readTail(v.tail, kLegacyTail, v);
  v.udp_sequence.reset();
  if (size == bare + 4) v.udp_sequence = u32(v.tail + kLegacyTailBytes);
  return {};
}

// Protocol 3.1 (QT64): a 12-byte header, 4-byte units, no CRC.
std::string parseQt31(const ModelSpec& spec, std::span<const std::uint8_t> payload, PacketView& v) {
  const std::uint8_t* p = payload.data();
  const std::uint8_t flags = p[11];
  if (flags & ~0x01u) return fail(spec, "flags " + hex(flags, 2) + " announce fields this decoder does not know");
  const bool has_sequence = flags & 0x01;
  const std::size_t body_end = kHeaderBytes + std::size_t(spec.blocks) * v.blockBytes();
  const std::size_t expected = body_end + kQt64TailBytes + (has_sequence ? 4 : 0);
  if (payload.size() != expected)
    return fail(spec, "size " + std::to_string(payload.size()) + ", expected " + std::to_string(expected) +
                          " for flags " + hex(flags, 2));
  v.tail = p + body_end;
  readTail(v.tail, kQt64Tail, v);
  v.udp_sequence.reset();
  if (has_sequence) v.udp_sequence = u32(v.tail + kQt64TailBytes);
  return {};
}

}  // namespace

std::string parsePacket(const ModelSpec& spec, std::span<const std::uint8_t> payload, PacketView& v) {
  const std::size_t size = payload.size();
  const std::uint8_t* p = payload.data();
  v.mode_flag = 0;
  v.has_crc = false;
  v.crc_ok = true;
  v.tail_crc_bytes = 0;
  v.block_prefix = 2;
  v.unit_bytes = 4;
  std::uint8_t return_num = 0;  // the header's return count, where the format has one
  if (spec.protocol == Protocol::kPandar40P || spec.protocol == Protocol::kPandar64) {
    if (std::string error = parseLegacy(spec, payload, v); !error.empty()) return error;
  } else {
    if (size < kHeaderBytes)
      return fail(spec, "size " + std::to_string(size) + ", shorter than the 12-byte header");
    if (p[0] != 0xEE || p[1] != 0xFF)
      return fail(spec, "start of packet " + hex(unsigned(p[0]) << 8 | p[1], 4) + ", expected 0xEEFF");
    if (p[2] != spec.protocol_major || p[3] != spec.protocol_minor)
      return fail(spec, "protocol version " + std::to_string(p[2]) + "." + std::to_string(p[3]) +
                            ", expected " + std::to_string(spec.protocol_major) + "." +
                            std::to_string(spec.protocol_minor));
    if (p[6] != spec.channels)
      return fail(spec, "laser_num " + std::to_string(p[6]) + ", expected " + std::to_string(spec.channels));
    if (p[7] != spec.blocks)
      return fail(spec, "block_num " + std::to_string(p[7]) + ", expected " + std::to_string(spec.blocks));
    if (p[9] == 0) return fail(spec, "dis_unit 0");
    return_num = p[10];
    // The XT32M2X announces the most returns it can send (3), not the ones in this packet.
    const std::uint8_t most_returns = spec.model == Model::kXT32M ? 3 : 2;
    if (return_num < 1 || return_num > most_returns)
      return fail(spec, "return_num " + std::to_string(return_num) +
                            (most_returns == 2 ? ", expected 1 or 2" : ", expected 1 to 3"));
    v.body = p + kHeaderBytes;
    v.channels = spec.channels;
    v.blocks = spec.blocks;
    v.dis_unit_mm = p[9];
    if (spec.protocol == Protocol::kQt31) {
      if (std::string error = parseQt31(spec, payload, v); !error.empty()) return error;
    } else if (std::string error = parseXtOrQt128(spec, payload, v); !error.empty()) {
      return error;
    }
  }

  const int n = returnsPerFiring(v.return_mode);
  if (n == 0) return fail(spec, "return mode " + hex(v.return_mode, 2) + " unknown");
  if (return_num != 0 && spec.model != Model::kXT32M && n != return_num)
    return fail(spec, "return mode " + hex(v.return_mode, 2) + " has " + std::to_string(n) +
                          " returns, header return_num " + std::to_string(return_num));
  if (spec.blocks % n != 0)
    return fail(spec, "return mode " + hex(v.return_mode, 2) + " does not fit " + std::to_string(spec.blocks) +
                          " blocks");
  v.returns = static_cast<std::uint8_t>(n);
  if (v.timestamp_us > 1'000'000)
    return fail(spec, "timestamp " + std::to_string(v.timestamp_us) + " us, above 1000000");
  for (int b = 0; b < v.blocks; ++b) {
    const std::uint16_t az = v.azimuth(b);
    if (az >= 36000)
      return fail(spec, "block " + std::to_string(b + 1) + " azimuth " + std::to_string(az) +
                            ", above 35999 (0.01 deg)");
    if (b % n != 0 && az != v.azimuth(b - b % n))
      return fail(spec, "block " + std::to_string(b + 1) + " azimuth " + std::to_string(az) +
                            " differs from its dual-return partner " +
                            std::to_string(v.azimuth(b - b % n)));
  }
  return {};
}

}  // namespace rigcal::drivers::hesai
