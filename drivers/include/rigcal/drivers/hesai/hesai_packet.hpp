#pragma once
// Hesai point-cloud packet formats: PandarXT16 / PandarXT32 / PandarXT32M (UDP protocol 6.1),
// PandarQT128 (QT128C2X, protocol 3.2), PandarQT64 (protocol 3.1), Pandar64 and Pandar40P (the
// older formats without a protocol version). Layouts and validation; the firing times are in
// hesai_firing_times.hpp, the packet CRC in hesai_crc.hpp, the decoding into points in hesai_decoder.hpp.
// All multi-byte fields are little endian.
//
// Protocol 6.1 (XT16: 568 bytes, XT32: 1080 bytes):
//   header 12 | 8 blocks × (azimuth u16 + channels × (distance u16, reflectivity u8, reserved u8)) |
//   tail 24 (reserved 9, high-temperature flag, return mode, motor rpm u16, date 6, µs timestamp u32,
//   factory byte) | udp_sequence u32.  No CRC.
// Protocol 3.2 (QT128C2X, 1127 bytes with every option on):
//   header 12 | 2 blocks × (azimuth u16 + 128 × 4 bytes) | CRC1 u32 (body) |
//   functional safety 17 (if flags bit 2; ends with its own CRC2) |
//   tail 26 (reserved 5, mode flag, reserved 6, return mode, motor rpm u16, date 6, µs timestamp u32,
//   factory byte) | udp_sequence u32 (if flags bit 0) | CRC3 u32 (tail + udp_sequence) |
//   digital signature 32 (if flags bit 3).
// Protocol 3.1 (QT64, 1072 bytes): header 12 | 4 blocks × (azimuth u16 + 64 × 4 bytes) |
//   tail 24 (reserved 10, motor rpm u16, µs timestamp u32, return mode, factory byte, date 6) |
//   udp_sequence u32 (if flags bit 0).
// Pandar64 (1194 or 1198 bytes): header 8 (0xEEFF, laser_num, block_num, reserved, dis_unit,
//   reserved 2) | 6 blocks × (azimuth u16 + 64 × (distance u16, reflectivity u8)) |
//   tail 22 (reserved 5, high-temperature flag, reserved 2, motor rpm u16, µs timestamp u32,
//   return mode, factory byte, date 6) | udp_sequence u32 (optional: told apart by the size).
// Pandar40P (1262 or 1266 bytes): no header, 4 mm unit | 10 blocks × (0xFFEE, azimuth u16,
//   40 × 3 bytes) | the Pandar64 tail | optional udp_sequence u32. Their date's year: yearBase().
// XT32M (PandarXT32M2X, 820 bytes) is protocol 6.1 with 6 blocks; its header return_num says 3
// (the most it can send), the tail's return mode says how many blocks one firing fills.
// The three CRCs are CRC-32/MPEG-2. They are checked and counted, never a reason to drop a packet:
// the manual does not make them mandatory for decoding.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>
#include <string_view>

namespace rigcal::drivers::hesai {

enum class Model : std::uint8_t { kXT16, kXT32, kQT128, kPandar40P, kPandar64, kQT64, kXT32M };

/// The wire formats: one layout table per protocol (hesai_packet.cpp).
enum class Protocol : std::uint8_t { kXt61, kQt32, kQt31, kPandar64, kPandar40P };

struct ModelSpec {
  Model model;
  std::string_view name;             // "PandarXT32", ...
  std::uint8_t protocol_major;
  std::uint8_t protocol_minor;
  std::uint16_t channels;
  std::uint16_t blocks;
  float min_range_m;                 // the sensor's own range limits
  float max_range_m;
  std::size_t max_points_per_scan;   // slowest rotation, dual return, every channel
  Protocol protocol;
  std::uint16_t year_base;           // the tail date's year counts from this (see yearBase())
};

/// The models this decoder reads, and lookup by exact name (nullptr when unknown).
std::span<const ModelSpec> allModels();
const ModelSpec* findModel(std::string_view name);

/// Return-mode byte of the tail.
namespace return_mode {
inline constexpr std::uint8_t kFirst = 0x33, kSecond = 0x34, kStrongest = 0x37, kLast = 0x38;
inline constexpr std::uint8_t kLastStrongest = 0x39, kFirstSecond = 0x3A, kFirstLast = 0x3B,
                              kFirstStrongest = 0x3C, kStrongestSecondStrongest = 0x3E;
}  // namespace return_mode

/// Returns stored per firing for a return-mode byte: 1, 2, or 0 when the byte is unknown.
int returnsPerFiring(std::uint8_t mode);

/// A validated packet: pointers into the payload (valid while it is).
struct PacketView {
  const std::uint8_t* body = nullptr;   // first block
  std::uint16_t channels = 0;
  std::uint16_t blocks = 0;
  std::uint8_t returns = 1;             // blocks per firing (1 single, 2 dual)
  std::uint8_t block_prefix = 2;        // bytes before a block's units (Pandar40P: 0xFFEE + azimuth)
  std::uint8_t unit_bytes = 4;          // bytes per channel (distance u16, reflectivity u8[, reserved])
  std::uint8_t dis_unit_mm = 4;
  std::uint8_t return_mode = 0;
  std::uint8_t mode_flag = 0;           // QT128: bit 0 set = firing sequence (loop) 1 in dual mode
  std::uint16_t motor_rpm = 0;
  std::array<std::uint8_t, 6> date{};   // year − 1900, month, day, hour, minute, second (UTC)
  std::uint32_t timestamp_us = 0;       // µs within that second
  std::optional<std::uint32_t> udp_sequence;
  bool has_crc = false;                 // protocol 3.2: CRC fields present
  bool crc_ok = true;                   // all present CRCs match
  const std::uint8_t* tail = nullptr;   // the tail (date at tailDateOffset(), µs at tailTimestampOffset())
  std::size_t tail_crc_bytes = 0;       // protocol 3.2: tail bytes CRC3 covers (it follows them); else 0

  [[nodiscard]] std::size_t blockBytes() const { return block_prefix + std::size_t(unit_bytes) * channels; }
  [[nodiscard]] const std::uint8_t* block(int b) const { return body + b * blockBytes(); }
  /// The first channel's unit of block b.
  [[nodiscard]] const std::uint8_t* units(int b) const { return block(b) + block_prefix; }
  [[nodiscard]] std::uint16_t azimuth(int b) const {
    const std::uint8_t* p = block(b) + block_prefix - 2;
    return static_cast<std::uint16_t>(p[0] | (p[1] << 8));
  }
};

/// Validates `payload` as a packet of `spec` and fills `view`. Returns "" on success, otherwise a
/// one-line reason naming the field, e.g. "PandarXT32 packet: size 1000, expected 1080".
/// CRCs are verified (view.crc_ok) but a mismatch is not an error.
std::string parsePacket(const ModelSpec& spec, std::span<const std::uint8_t> payload, PacketView& view);

/// True for Hesai GPS/PPS packets (512 bytes starting 0xFF 0xEE) that may share the data port.
bool isGpsPacket(std::span<const std::uint8_t> payload);

/// Seconds since the UNIX epoch of the tail date (year − year_base, month, day, hour, minute,
/// second), independent of the local time zone; nullopt when a field is out of range.
std::optional<std::int64_t> utcSeconds(const std::array<std::uint8_t, 6>& date, int year_base = 1900);

/// The year the tail's year byte counts from. The Pandar40P and Pandar64 manuals say 2000, but units
/// also send years since 1900 (the Pandar64 capture here says 120 for 2020): for those two a byte of
/// 100 or more counts from 1900 (2000 onwards either way). Other models: 1900, as their manuals say.
int yearBase(const ModelSpec& spec, std::uint8_t year_byte);

/// Where the tail date (6 bytes) and the µs timestamp (u32) start in the tail of `spec`'s packets.
std::size_t tailDateOffset(const ModelSpec& spec);
std::size_t tailTimestampOffset(const ModelSpec& spec);

}  // namespace rigcal::drivers::hesai
