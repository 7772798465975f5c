#include "rigcal/drivers/hesai/hesai_packet.hpp"

#include <algorithm>

#include "rigcal/core/civil_date.hpp"
#include "rigcal/drivers/hesai/hesai_crc.hpp"

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
