#pragma once
// Byte layout of Ouster lidar UDP packets, per udp_profile_lidar (firmware 1.12 to 3.x).
//
// LEGACY: no packet header/footer; each column is a 16-byte header (timestamp u64 ns, measurement_id
//   u16, frame_id u16, encoder count u32), pixels of 12 bytes, and a 4-byte footer (status u32,
//   0xffffffff = valid).
// Every other profile ("eUDP"): a 32-byte packet header (packet_type u16 = 1, frame_id u16, init_id u24,
//   serial u40, alert flags, thermal / shot-limiting countdowns and states), columns of a 12-byte header
//   (timestamp u64 ns, measurement_id u16, status u16, bit 0 = valid) and pixels, then a 32-byte packet
//   footer whose last 8 bytes carry a CRC-64 (ECMA-182, reflected) of the rest of the packet on firmware
//   3.1 and later. FUSA_RNG15_RFL8_NIR8_DUAL differs in the header: packet_type u8, init_id u24 at byte 1,
//   frame_id u32 at byte 4, serial u40 at byte 11.
// Pixel fields (little-endian words; ranges in millimetres after scaling):
//   LEGACY                       range u20 @0, reflectivity u8 @4, signal u16 @6, near_ir u16 @8
//   RNG19_RFL8_SIG16_NIR16       range u19 @0, reflectivity u8 @4, signal u16 @6, near_ir u16 @8
//   RNG19_RFL8_SIG16_NIR16_DUAL  range u19 @0, refl u8 @3, range2 u19 @4, refl2 u8 @7, signal u16 @8,
//                                signal2 u16 @10, near_ir u16 @12
//   RNG15_RFL8_NIR8 (low rate)   range u15 @0 in units of 8 mm, refl u8 @2, near_ir u8 @3 (×16)
//   FUSA_RNG15_RFL8_NIR8_DUAL    as RNG15 for the first return, then range2 u15 @4 (8 mm), refl2 u8 @6
//   FIVE_WORD_PIXEL              as DUAL, 20-byte pixels
// All readers take pointers into a buffer the caller has size-checked against packet_size.
#include <bit>
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <optional>
#include <string>
#include <string_view>

namespace rigcal::drivers::ouster {

static_assert(std::endian::native == std::endian::little, "Ouster packets are read as little-endian");

enum class UdpProfile : std::uint8_t {
  kLegacy,
  kRng19Rfl8Sig16Nir16,
  kRng19Rfl8Sig16Nir16Dual,
  kRng15Rfl8Nir8,
  kFusaRng15Rfl8Nir8Dual,
  kFiveWordPixel,
};

/// "LEGACY", "RNG19_RFL8_SIG16_NIR16", ...; nullopt for a name we do not know.
std::optional<UdpProfile> udpProfileFromString(std::string_view name);
std::string_view toString(UdpProfile profile);

inline constexpr std::size_t kImuPacketSize = 48;  // legacy IMU packet (may share the lidar port)

template <class T>
inline T loadLe(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}

/// One pixel's fields, raw (ranges in mm, already scaled for the 8 mm profiles).
struct PixelFields {
  std::uint32_t range = 0, range2 = 0;
  std::uint8_t reflectivity = 0, reflectivity2 = 0;
  std::uint16_t signal = 0, signal2 = 0, near_ir = 0;
};

/// Compile-time pixel layout per profile, for the decoder's hot loop (see the table above).
template <UdpProfile P>
struct PixelLayout;

template <>
struct PixelLayout<UdpProfile::kLegacy> {
  static constexpr std::size_t kSize = 12;
  static constexpr bool kDual = false;
  static std::uint32_t range(const std::uint8_t* px) { return loadLe<std::uint32_t>(px) & 0xfffffu; }
  static std::uint8_t reflectivity(const std::uint8_t* px) { return px[4]; }
  static std::uint32_t range2(const std::uint8_t*) { return 0; }
  static std::uint8_t reflectivity2(const std::uint8_t*) { return 0; }
  static std::uint16_t signal(const std::uint8_t* px) { return loadLe<std::uint16_t>(px + 6); }
  static std::uint16_t signal2(const std::uint8_t*) { return 0; }
  static std::uint16_t nearIr(const std::uint8_t* px) { return loadLe<std::uint16_t>(px + 8); }
};

template <>
struct PixelLayout<UdpProfile::kRng19Rfl8Sig16Nir16> : PixelLayout<UdpProfile::kLegacy> {
  static std::uint32_t range(const std::uint8_t* px) { return loadLe<std::uint32_t>(px) & 0x7ffffu; }
};

template <>
struct PixelLayout<UdpProfile::kRng19Rfl8Sig16Nir16Dual> {
  static constexpr std::size_t kSize = 16;
  static constexpr bool kDual = true;
  static std::uint32_t range(const std::uint8_t* px) { return loadLe<std::uint32_t>(px) & 0x7ffffu; }
  static std::uint8_t reflectivity(const std::uint8_t* px) { return px[3]; }
  static std::uint32_t range2(const std::uint8_t* px) { return loadLe<std::uint32_t>(px + 4) & 0x7ffffu; }
  static std::uint8_t reflectivity2(const std::uint8_t* px) { return px[7]; }
  static std::uint16_t signal(const std::uint8_t* px) { return loadLe<std::uint16_t>(px + 8); }
  static std::uint16_t signal2(const std::uint8_t* px) { return loadLe<std::uint16_t>(px + 10); }
  static std::uint16_t nearIr(const std::uint8_t* px) { return loadLe<std::uint16_t>(px + 12); }
};

template <>
struct PixelLayout<UdpProfile::kFiveWordPixel> : PixelLayout<UdpProfile::kRng19Rfl8Sig16Nir16Dual> {
  static constexpr std::size_t kSize = 20;
};

template <>
struct PixelLayout<UdpProfile::kRng15Rfl8Nir8> {
  static constexpr std::size_t kSize = 4;
  static constexpr bool kDual = false;
  static std::uint32_t range(const std::uint8_t* px) {
    return std::uint32_t(loadLe<std::uint16_t>(px) & 0x7fffu) << 3;  // 8 mm units
  }
  static std::uint8_t reflectivity(const std::uint8_t* px) { return px[2]; }
  static std::uint32_t range2(const std::uint8_t*) { return 0; }
  static std::uint8_t reflectivity2(const std::uint8_t*) { return 0; }
  static std::uint16_t signal(const std::uint8_t*) { return 0; }
  static std::uint16_t signal2(const std::uint8_t*) { return 0; }
  static std::uint16_t nearIr(const std::uint8_t* px) { return std::uint16_t(px[3] << 4); }
};

template <>
struct PixelLayout<UdpProfile::kFusaRng15Rfl8Nir8Dual> : PixelLayout<UdpProfile::kRng15Rfl8Nir8> {
  static constexpr std::size_t kSize = 8;
  static constexpr bool kDual = true;
  static std::uint32_t range2(const std::uint8_t* px) {
    return std::uint32_t(loadLe<std::uint16_t>(px + 4) & 0x7fffu) << 3;
  }
  static std::uint8_t reflectivity2(const std::uint8_t* px) { return px[6]; }
};

class PacketFormat {
 public:
  /// Throws std::invalid_argument when the layout is impossible (zero sizes, packet > 65535 bytes).
  PacketFormat(UdpProfile profile, int pixels_per_column, int columns_per_packet);

  UdpProfile profile;
  int pixels_per_column;
  int columns_per_packet;
  std::size_t packet_header_size, column_header_size, pixel_size, column_footer_size, packet_footer_size;
  std::size_t column_size;
  std::size_t packet_size;

  [[nodiscard]] bool legacy() const { return profile == UdpProfile::kLegacy; }
  [[nodiscard]] bool fusa() const { return profile == UdpProfile::kFusaRng15Rfl8Nir8Dual; }
  [[nodiscard]] bool dual() const {
    return profile == UdpProfile::kRng19Rfl8Sig16Nir16Dual || profile == UdpProfile::kFusaRng15Rfl8Nir8Dual ||
           profile == UdpProfile::kFiveWordPixel;
  }
  [[nodiscard]] bool hasSignal() const {
    return profile != UdpProfile::kRng15Rfl8Nir8 && profile != UdpProfile::kFusaRng15Rfl8Nir8Dual;
  }

  // Packet header (eUDP); LEGACY packets carry the frame id in each column header instead.
  [[nodiscard]] std::uint16_t packetType(const std::uint8_t* p) const {
    if (legacy()) return 0;
    return fusa() ? p[0] : loadLe<std::uint16_t>(p);
  }
  [[nodiscard]] std::uint32_t frameId(const std::uint8_t* p) const {
    if (legacy()) return loadLe<std::uint16_t>(p + 10);  // first column's header
    return fusa() ? loadLe<std::uint32_t>(p + 4) : loadLe<std::uint16_t>(p + 2);
  }
  /// Frame ids wrap at 2^16 (2^32 for FUSA).
  [[nodiscard]] std::uint64_t frameIdModulus() const { return fusa() ? (1ull << 32) : (1ull << 16); }
  [[nodiscard]] std::uint32_t initId(const std::uint8_t* p) const {
    if (legacy()) return 0;
    return loadLe<std::uint32_t>(p + (fusa() ? 1 : 4)) & 0x00ffffffu;
  }
  [[nodiscard]] std::uint64_t serial(const std::uint8_t* p) const {
    if (legacy()) return 0;
    return loadLe<std::uint64_t>(p + (fusa() ? 11 : 7)) & 0xffffffffffull;
  }
  [[nodiscard]] std::uint8_t thermalShutdown(const std::uint8_t* p) const { return legacy() ? 0 : p[18] & 0x0f; }
  [[nodiscard]] std::uint8_t shotLimiting(const std::uint8_t* p) const { return legacy() ? 0 : p[19] & 0x0f; }
  /// The CRC-64 stored in the last 8 bytes of an eUDP footer (firmware ≥ 3.1).
  [[nodiscard]] std::uint64_t footerCrc(const std::uint8_t* p) const { return loadLe<std::uint64_t>(p + packet_size - 8); }

  // Columns.
  [[nodiscard]] const std::uint8_t* column(const std::uint8_t* p, int i) const {
    return p + packet_header_size + std::size_t(i) * column_size;
  }
  [[nodiscard]] static std::uint64_t columnTimestamp(const std::uint8_t* col) { return loadLe<std::uint64_t>(col); }
  [[nodiscard]] static std::uint16_t columnMeasurementId(const std::uint8_t* col) {
    return loadLe<std::uint16_t>(col + 8);
  }
  [[nodiscard]] std::uint32_t columnStatus(const std::uint8_t* col) const {
    if (legacy()) return loadLe<std::uint32_t>(col + column_size - 4);
    return loadLe<std::uint16_t>(col + 10);
  }
  [[nodiscard]] static bool statusValid(std::uint32_t status) { return (status & 1u) != 0; }
  [[nodiscard]] const std::uint8_t* pixel(const std::uint8_t* col, int row) const {
    return col + column_header_size + std::size_t(row) * pixel_size;
  }

  /// Every field of one pixel (the slow, general path: raw scans, tests).
  [[nodiscard]] PixelFields pixelFields(const std::uint8_t* px) const;
};

/// CRC-64/XZ (ECMA-182 polynomial, reflected, init and final xor all ones).
std::uint64_t crc64(const std::uint8_t* data, std::size_t size);

}  // namespace rigcal::drivers::ouster
