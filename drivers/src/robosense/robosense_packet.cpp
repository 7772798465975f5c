#include "rigcal/drivers/robosense/robosense_packet.hpp"

namespace rigcal::drivers::robosense {
namespace {

std::uint32_t be16(const std::uint8_t* p) { return std::uint32_t(p[0]) << 8 | p[1]; }
std::uint32_t be32(const std::uint8_t* p) { return be16(p) << 16 | be16(p + 2); }

constexpr std::size_t kDifopRpm = 8;
constexpr std::size_t kDifopFov = 32;
constexpr std::size_t kDifopReturnMode = 300;
constexpr std::size_t kDifopVertical = 468;
constexpr std::size_t kDifopHorizontal = 564;

}  // namespace

std::uint16_t MsopView::azimuth(int block) const {
  return std::uint16_t(be16(data + kHeaderSize + std::size_t(block) * kBlockSize + 2));
}

std::string parseMsop(std::span<const std::uint8_t> p, MsopView& view) {
  if (p.size() != kPacketSize)
    return "RS-Helios-16P MSOP packet: size " + std::to_string(p.size()) + " B, expected " + std::to_string(kPacketSize);
  if (!isMsop(p)) return "RS-Helios-16P packet: header id is not 55 AA 05 5A (MSOP) nor the DIFOP id";
  view.data = p.data();
  for (int b = 0; b < kBlocks; ++b) {
    const std::uint8_t* blk = p.data() + kHeaderSize + std::size_t(b) * kBlockSize;
    if (blk[0] != 0xFF || blk[1] != 0xEE)
      return "RS-Helios-16P MSOP packet: block " + std::to_string(b) + " id is not FF EE";
    if (view.azimuth(b) >= 36000)
      return "RS-Helios-16P MSOP packet: block " + std::to_string(b) + " azimuth " + std::to_string(view.azimuth(b)) +
             " is not below 36000 (0.01°)";
  }
  const std::uint8_t* ts = p.data() + kTimestampOffset;
  view.seconds = std::uint64_t(be16(ts)) << 32 | be32(ts + 2);
  view.microseconds = be32(ts + 6);
  if (view.microseconds >= 1'000'000)
    return "RS-Helios-16P MSOP packet: timestamp µs field " + std::to_string(view.microseconds) + " is not below 1000000";
  // A u48 of seconds reaches past what int64 nanoseconds hold (year 2262): such a clock is corrupt.
  if (view.seconds > kMaxTimestampSeconds)
    return "RS-Helios-16P MSOP packet: timestamp seconds field " + std::to_string(view.seconds) +
           " is beyond " + std::to_string(kMaxTimestampSeconds) + " (year 2255)";
  view.counter = be32(p.data() + kCounterOffset);
  return {};
}

std::string parseDifop(std::span<const std::uint8_t> p, DeviceInfo& info) {
  if (p.size() != kPacketSize)
    return "RS-Helios-16P DIFOP packet: size " + std::to_string(p.size()) + " B, expected " + std::to_string(kPacketSize);
  if (!isDifop(p)) return "RS-Helios-16P DIFOP packet: header id is not A5 FF 00 5A 11 11 55 55";
  DeviceInfo d;
  d.rpm = std::uint16_t(be16(p.data() + kDifopRpm));
  d.fov_start = std::uint16_t(be16(p.data() + kDifopFov));
  d.fov_end = std::uint16_t(be16(p.data() + kDifopFov + 2));
  if (d.fov_start > 36000 || d.fov_end > 36000)
    return "RS-Helios-16P DIFOP packet: FOV " + std::to_string(d.fov_start) + ".." + std::to_string(d.fov_end) +
           " is outside 0..36000 (0.01°)";
  switch (p[kDifopReturnMode]) {
    case 0x00: d.return_mode = ReturnMode::kDual; break;
    case 0x05: d.return_mode = ReturnMode::kLast; break;
    case 0x06: d.return_mode = ReturnMode::kNearest; break;
    default: d.return_mode = ReturnMode::kStrongest; break;  // 0x04 and unknown codes, as rs_driver
  }
  for (int l = 0; l < kLasers; ++l) {
    for (int which = 0; which < 2; ++which) {
      const std::uint8_t* a = p.data() + (which == 0 ? kDifopVertical : kDifopHorizontal) + 3 * std::size_t(l);
      if (a[0] == 0xFF)
        return std::string("RS-Helios-16P DIFOP packet: ") + (which == 0 ? "vertical" : "horizontal") +
               " angle of laser " + std::to_string(l) + " is not written (sign byte FF)";
      const std::int32_t v = a[0] == 0 ? std::int32_t(be16(a + 1)) : -std::int32_t(be16(a + 1));
      if (v < -9000 || v >= 9000)
        return std::string("RS-Helios-16P DIFOP packet: ") + (which == 0 ? "vertical" : "horizontal") +
               " angle of laser " + std::to_string(l) + " is " + std::to_string(v) + " (0.01°), outside ±90°";
      (which == 0 ? d.vertical : d.horizontal)[std::size_t(l)] = v;
    }
  }
  info = d;
  return {};
}

bool writeMsopTime(std::span<std::uint8_t> p, std::uint64_t seconds, std::uint32_t microseconds) {
  if (p.size() != kPacketSize || !isMsop(p) || seconds >> 48 != 0 || microseconds >= 1'000'000) return false;
  std::uint8_t* ts = p.data() + kTimestampOffset;
  for (int i = 0; i < 6; ++i) ts[i] = std::uint8_t(seconds >> (8 * (5 - i)));
  for (int i = 0; i < 4; ++i) ts[6 + i] = std::uint8_t(microseconds >> (8 * (3 - i)));
  return true;
}

}  // namespace rigcal::drivers::robosense
