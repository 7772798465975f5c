#pragma once
// RoboSense RS-Helios-16P wire format: MSOP data packets and the DIFOP device-information packet.
// Layouts as documented by RoboSense's rs_driver (RSHELIOSMsopPkt / RSHELIOSDifopPkt) and nebula's
// RoboSense decoders; all multi-byte fields are big-endian.
//
// MSOP (1248 B, default port 6699):
//   header 42 B: id 55 AA 05 5A · u16 protocol version · ... · u32 packet counter @12 ·
//                timestamp @20 (u48 UTC seconds, u32 µs) · u8 lidar type @30 · ... · temperature @38
//   12 blocks × 100 B @42: id FF EE · u16 azimuth (0.01°) · 32 channels × {u16 distance (2.5 mm), u8 intensity}
//   tail 6 B: u32 index, u16 tail
// DIFOP (1248 B, default port 7788): id A5 FF 00 5A 11 11 55 55 · u16 rpm @8 · FOV start/end (0.01°) @32/@34 ·
//   u8 return mode @300 (0x00 dual; 0x04 strongest, 0x05 last, 0x06 nearest) ·
//   vertical angles @468 and horizontal offsets @564: per laser {u8 sign (0 +, else −), u16 value, 0.01°}.
#include <array>
#include <cstdint>
#include <optional>
#include <span>
#include <string>

namespace rigcal::drivers::robosense {

inline constexpr std::size_t kPacketSize = 1248;  // MSOP and DIFOP
inline constexpr int kLasers = 16;
inline constexpr int kBlocks = 12;
inline constexpr int kChannelsPerBlock = 32;
inline constexpr std::size_t kHeaderSize = 42;
inline constexpr std::size_t kBlockSize = 100;
inline constexpr std::size_t kTimestampOffset = 20;  // u48 seconds + u32 µs
inline constexpr std::uint64_t kMaxTimestampSeconds = 9'000'000'000;  // int64 ns hold up to 9.22e9 s
inline constexpr std::size_t kCounterOffset = 12;
inline constexpr double kDistanceUnitM = 0.0025;
inline constexpr double kSensorMinRangeM = 0.1;
inline constexpr double kSensorMaxRangeM = 180.0;
inline constexpr std::uint16_t kDefaultMsopPort = 6699;
inline constexpr std::uint16_t kDefaultDifopPort = 7788;

inline bool isMsop(std::span<const std::uint8_t> p) {
  return p.size() >= 4 && p[0] == 0x55 && p[1] == 0xAA && p[2] == 0x05 && p[3] == 0x5A;
}
inline bool isDifop(std::span<const std::uint8_t> p) {
  static constexpr std::uint8_t kId[8] = {0xA5, 0xFF, 0x00, 0x5A, 0x11, 0x11, 0x55, 0x55};
  if (p.size() < 8) return false;
  for (int i = 0; i < 8; ++i)
    if (p[std::size_t(i)] != kId[i]) return false;
  return true;
}

/// A checked view of one MSOP packet (the bytes stay in the caller's buffer).
struct MsopView {
  const std::uint8_t* data = nullptr;
  std::uint32_t counter = 0;
  std::uint64_t seconds = 0;       // UTC seconds (sensor clock)
  std::uint32_t microseconds = 0;  // < 1'000'000
  [[nodiscard]] std::uint16_t azimuth(int block) const;  // 0.01°, < 36000
  [[nodiscard]] const std::uint8_t* channels(int block) const { return data + kHeaderSize + std::size_t(block) * kBlockSize + 4; }
};

/// Checks size, magic, block ids, azimuths and the timestamp. Returns "" or a one-line reason naming the field.
std::string parseMsop(std::span<const std::uint8_t> payload, MsopView& view);

enum class ReturnMode : std::uint8_t { kDual, kStrongest, kLast, kNearest };

/// What the decoder takes from a DIFOP packet.
struct DeviceInfo {
  std::uint16_t rpm = 600;
  std::uint16_t fov_start = 0, fov_end = 36000;  // 0.01°
  ReturnMode return_mode = ReturnMode::kStrongest;
  std::array<std::int32_t, kLasers> vertical{};    // 0.01°
  std::array<std::int32_t, kLasers> horizontal{};  // 0.01°
};

/// Parses a DIFOP packet. Returns "" or a one-line reason naming the field.
std::string parseDifop(std::span<const std::uint8_t> payload, DeviceInfo& info);

/// Writes the MSOP timestamp (restamping); false when `payload` is not an MSOP packet.
bool writeMsopTime(std::span<std::uint8_t> payload, std::uint64_t seconds, std::uint32_t microseconds);

}  // namespace rigcal::drivers::robosense
