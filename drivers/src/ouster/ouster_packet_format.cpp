#include "rigcal/drivers/ouster/ouster_packet_format.hpp"

#include <array>
#include <stdexcept>

namespace rigcal::drivers::ouster {
namespace {

struct ProfileName {
  UdpProfile profile;
  std::string_view name;
};
constexpr std::array<ProfileName, 6> kProfileNames{{
    {UdpProfile::kLegacy, "LEGACY"},
    {UdpProfile::kRng19Rfl8Sig16Nir16, "RNG19_RFL8_SIG16_NIR16"},
    {UdpProfile::kRng19Rfl8Sig16Nir16Dual, "RNG19_RFL8_SIG16_NIR16_DUAL"},
    {UdpProfile::kRng15Rfl8Nir8, "RNG15_RFL8_NIR8"},
    {UdpProfile::kFusaRng15Rfl8Nir8Dual, "FUSA_RNG15_RFL8_NIR8_DUAL"},
    {UdpProfile::kFiveWordPixel, "FIVE_WORD_PIXEL"},
}};

std::size_t pixelSize(UdpProfile p) {
  switch (p) {
    case UdpProfile::kLegacy: return PixelLayout<UdpProfile::kLegacy>::kSize;
    case UdpProfile::kRng19Rfl8Sig16Nir16: return PixelLayout<UdpProfile::kRng19Rfl8Sig16Nir16>::kSize;
    case UdpProfile::kRng19Rfl8Sig16Nir16Dual: return PixelLayout<UdpProfile::kRng19Rfl8Sig16Nir16Dual>::kSize;
    case UdpProfile::kRng15Rfl8Nir8: return PixelLayout<UdpProfile::kRng15Rfl8Nir8>::kSize;
    case UdpProfile::kFusaRng15Rfl8Nir8Dual: return PixelLayout<UdpProfile::kFusaRng15Rfl8Nir8Dual>::kSize;
    case UdpProfile::kFiveWordPixel: return PixelLayout<UdpProfile::kFiveWordPixel>::kSize;
  }
  return 0;
}

template <UdpProfile P>
PixelFields readPixel(const std::uint8_t* px) {
  using L = PixelLayout<P>;
  PixelFields f;
  f.range = L::range(px);
  f.range2 = L::range2(px);
  f.reflectivity = L::reflectivity(px);
  f.reflectivity2 = L::reflectivity2(px);
  f.signal = L::signal(px);
  f.signal2 = L::signal2(px);
  f.near_ir = L::nearIr(px);
  return f;
}

// Slicing-by-8 tables for the reflected CRC-64/XZ: table[0] is the byte-wise table, table[k][i] the
// CRC of byte i followed by k zero bytes.
using CrcTables = std::array<std::array<std::uint64_t, 256>, 8>;
constexpr CrcTables makeCrcTables() {
  constexpr std::uint64_t kPoly = 0xC96C5795D7870F42ull;  // ECMA-182, reflected
  CrcTables t{};
  for (std::uint64_t i = 0; i < 256; ++i) {
    std::uint64_t r = i;
    for (int j = 0; j < 8; ++j) r = (r & 1) ? (r >> 1) ^ kPoly : r >> 1;
    t[0][i] = r;
  }
  for (std::size_t k = 1; k < 8; ++k)
    for (std::size_t i = 0; i < 256; ++i) t[k][i] = (t[k - 1][i] >> 8) ^ t[0][t[k - 1][i] & 0xff];
  return t;
}
constexpr CrcTables kCrc = makeCrcTables();

}  // namespace

std::optional<UdpProfile> udpProfileFromString(std::string_view name) {
  for (const auto& p : kProfileNames)
    if (p.name == name) return p.profile;
  return std::nullopt;
}

std::string_view toString(UdpProfile profile) {
  for (const auto& p : kProfileNames)
    if (p.profile == profile) return p.name;
  return "UNKNOWN";
}

PacketFormat::PacketFormat(UdpProfile profile_, int pixels_per_column_, int columns_per_packet_)
    : profile(profile_), pixels_per_column(pixels_per_column_), columns_per_packet(columns_per_packet_) {
  if (pixels_per_column <= 0 || columns_per_packet <= 0)
    throw std::invalid_argument("Ouster packet format: pixels_per_column and columns_per_packet must be > 0");
  const bool leg = legacy();
  packet_header_size = leg ? 0 : 32;
  column_header_size = leg ? 16 : 12;
  pixel_size = pixelSize(profile);
  column_footer_size = leg ? 4 : 0;
  packet_footer_size = leg ? 0 : 32;
  const std::size_t ppc = std::size_t(pixels_per_column), cpp = std::size_t(columns_per_packet);
  column_size = column_header_size + ppc * pixel_size + column_footer_size;
  packet_size = packet_header_size + cpp * column_size + packet_footer_size;
  if (ppc > 65535 || cpp > 65535 || packet_size > 65535)
    throw std::invalid_argument("Ouster packet format: lidar packet of " + std::to_string(packet_size) +
                                " bytes exceeds 65535");
}

PixelFields PacketFormat::pixelFields(const std::uint8_t* px) const {
  switch (profile) {
    case UdpProfile::kLegacy: return readPixel<UdpProfile::kLegacy>(px);
    case UdpProfile::kRng19Rfl8Sig16Nir16: return readPixel<UdpProfile::kRng19Rfl8Sig16Nir16>(px);
    case UdpProfile::kRng19Rfl8Sig16Nir16Dual: return readPixel<UdpProfile::kRng19Rfl8Sig16Nir16Dual>(px);
    case UdpProfile::kRng15Rfl8Nir8: return readPixel<UdpProfile::kRng15Rfl8Nir8>(px);
    case UdpProfile::kFusaRng15Rfl8Nir8Dual: return readPixel<UdpProfile::kFusaRng15Rfl8Nir8Dual>(px);
    case UdpProfile::kFiveWordPixel: return readPixel<UdpProfile::kFiveWordPixel>(px);
  }
  return {};
}

std::uint64_t crc64(const std::uint8_t* data, std::size_t size) {
  std::uint64_t crc = ~0ull;
  std::size_t i = 0;
  for (; i + 8 <= size; i += 8) {
    crc ^= loadLe<std::uint64_t>(data + i);
    crc = kCrc[7][crc & 0xff] ^ kCrc[6][(crc >> 8) & 0xff] ^ kCrc[5][(crc >> 16) & 0xff] ^
          kCrc[4][(crc >> 24) & 0xff] ^ kCrc[3][(crc >> 32) & 0xff] ^ kCrc[2][(crc >> 40) & 0xff] ^
          kCrc[1][(crc >> 48) & 0xff] ^ kCrc[0][crc >> 56];
  }
  for (; i < size; ++i) crc = kCrc[0][(crc ^ data[i]) & 0xff] ^ (crc >> 8);
  return ~crc;
}

}  // namespace rigcal::drivers::ouster
