#include "rigcal/drivers/packet_restamper.hpp"

#include <algorithm>
#include <cstring>
#include <optional>
#include <stdexcept>

#include "rigcal/core/civil_date.hpp"
#include "rigcal/drivers/hesai/hesai_packet.hpp"
#include "rigcal/drivers/hesai/hesai_crc.hpp"
#include "rigcal/drivers/ouster/ouster_decoder.hpp"
#include "rigcal/drivers/ouster/ouster_metadata.hpp"
#include "rigcal/drivers/ouster/ouster_packet_format.hpp"
#include "rigcal/drivers/robosense/robosense_decoder.hpp"
#include "rigcal/drivers/robosense/robosense_packet.hpp"
#include "rigcal/drivers/velodyne/velodyne_decoder.hpp"
#include "rigcal/drivers/velodyne/velodyne_packet.hpp"

namespace rigcal::drivers {

namespace {

template <class T>
T load(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof v);
  return v;
}
template <class T>
void store(std::uint8_t* p, T v) {
  std::memcpy(p, &v, sizeof v);
}

std::int64_t floorMod(std::int64_t a, std::int64_t m) { return ((a % m) + m) % m; }

enum class PacketVendor : std::uint8_t { kVelodyne, kOuster, kHesai, kRobosense };

}  // namespace

struct PacketRestamper::Impl {
  PacketVendor vendor = PacketVendor::kVelodyne;
  std::optional<ouster::PacketFormat> ouster_format;
  bool ouster_crc = false;
  const hesai::ModelSpec* hesai_spec = nullptr;

  bool velodyne(std::span<std::uint8_t> p, std::int64_t shift_us) const {
    if (p.size() != velodyne::kDataPacketSize) return false;
    std::uint8_t* at = p.data() + velodyne::kTimestampOffset;
    const std::uint32_t us = load<std::uint32_t>(at);
    if (us >= velodyne::kMicrosPerHour) return false;
    store(at, std::uint32_t(floorMod(std::int64_t(us) + shift_us, velodyne::kMicrosPerHour)));
    return true;
  }

  bool ouster(std::span<std::uint8_t> p, std::int64_t shift_us) const {
    const ouster::PacketFormat& f = *ouster_format;
    if (p.size() != f.packet_size) return false;  // an IMU packet, or another sensor's
    for (int c = 0; c < f.columns_per_packet; ++c) {
      std::uint8_t* col = p.data() + f.packet_header_size + std::size_t(c) * f.column_size;
      const auto ns = load<std::uint64_t>(col);
      if (ns == 0) continue;  // a column the sensor did not fill (outside its window)
      store(col, std::uint64_t(std::int64_t(ns) + shift_us * 1000));
    }
    if (ouster_crc) store(p.data() + p.size() - 8, ouster::crc64(p.data(), p.size() - 8));
    return true;
  }

  bool hesai(std::span<std::uint8_t> p, std::int64_t shift_us) const {
    hesai::PacketView v;
    if (!hesai::parsePacket(*hesai_spec, p, v).empty()) return false;
    // Pandar40P / Pandar64 count years from 2000 or 1900: the restamped packet keeps the original's way.
    const int year_base = hesai::yearBase(*hesai_spec, v.date[0]);
    const auto seconds = hesai::utcSeconds(v.date, year_base);
    if (!seconds) return false;
    const std::int64_t t_us = *seconds * 1'000'000 + std::int64_t(v.timestamp_us) + shift_us;
    const std::int64_t s = t_us >= 0 ? t_us / 1'000'000 : (t_us - 999'999) / 1'000'000;
    const std::int64_t days = s >= 0 ? s / 86400 : (s - 86399) / 86400;
    const std::int64_t in_day = s - days * 86400;
    const CivilDate date = civilFromDays(days);
    if (date.year < year_base || date.year > year_base + (year_base == 2000 ? 99 : 255)) return false;
    auto* tail = p.data() + (v.tail - p.data());  // the same bytes, writable
    const std::size_t date_at = hesai::tailDateOffset(*hesai_spec);
    const std::uint8_t fields[6] = {std::uint8_t(date.year - year_base), std::uint8_t(date.month),
                                    std::uint8_t(date.day),           std::uint8_t(in_day / 3600),
                                    std::uint8_t(in_day / 60 % 60),   std::uint8_t(in_day % 60)};
    std::memcpy(tail + date_at, fields, 6);
    store(tail + hesai::tailTimestampOffset(*hesai_spec), std::uint32_t(t_us - s * 1'000'000));
    if (v.tail_crc_bytes > 0)
      store(tail + v.tail_crc_bytes, hesai::crc32Mpeg2({tail, v.tail_crc_bytes}));
    return true;
  }

  // RoboSense MSOP: the header's u48 UTC seconds + u32 µs (no checksum). DIFOP packets stay as they are.
  static bool robosense(std::span<std::uint8_t> p, std::int64_t shift_us) {
    robosense::MsopView v;
    if (!robosense::parseMsop(p, v).empty()) return false;
    const std::int64_t t_us = std::int64_t(v.seconds) * 1'000'000 + v.microseconds + shift_us;
    if (t_us < 0) return false;
    return robosense::writeMsopTime(p, std::uint64_t(t_us / 1'000'000), std::uint32_t(t_us % 1'000'000));
  }
};

PacketRestamper::PacketRestamper(const DecoderConfig& sensor) : impl_(std::make_unique<Impl>()) {
  const auto velodyne_models = velodyneModels();
  if (std::find(velodyne_models.begin(), velodyne_models.end(), sensor.model) != velodyne_models.end()) {
    impl_->vendor = PacketVendor::kVelodyne;
  } else if (const hesai::ModelSpec* spec = hesai::findModel(sensor.model)) {
    impl_->vendor = PacketVendor::kHesai;
    impl_->hesai_spec = spec;
  } else if (const auto robosense_models = robosenseModels();
             std::find(robosense_models.begin(), robosense_models.end(), sensor.model) != robosense_models.end()) {
    impl_->vendor = PacketVendor::kRobosense;
  } else if (const auto ouster_models = ousterModels();
             std::find(ouster_models.begin(), ouster_models.end(), sensor.model) != ouster_models.end()) {
    if (sensor.metadata.empty())
      throw std::runtime_error("Ouster " + sensor.model + ": restamping needs its metadata (sensor_info JSON)");
    const ouster::Metadata md = ouster::parseMetadataFile(sensor.metadata);
    impl_->vendor = PacketVendor::kOuster;
    impl_->ouster_format.emplace(md.profile, md.pixels_per_column, md.columns_per_packet);
    impl_->ouster_crc = md.crcFooter();
  } else {
    throw std::runtime_error("cannot restamp packets of lidar model '" + sensor.model + "'");
  }
}

PacketRestamper::~PacketRestamper() = default;
PacketRestamper::PacketRestamper(PacketRestamper&&) noexcept = default;
PacketRestamper& PacketRestamper::operator=(PacketRestamper&&) noexcept = default;

bool PacketRestamper::restamp(std::span<std::uint8_t> payload, std::int64_t shift_us) const {
  switch (impl_->vendor) {
    case PacketVendor::kVelodyne: return impl_->velodyne(payload, shift_us);
    case PacketVendor::kOuster: return impl_->ouster(payload, shift_us);
    case PacketVendor::kHesai: return impl_->hesai(payload, shift_us);
    case PacketVendor::kRobosense: return Impl::robosense(payload, shift_us);
  }
  return false;
}

}  // namespace rigcal::drivers
