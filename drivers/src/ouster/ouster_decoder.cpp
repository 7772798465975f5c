#include "rigcal/drivers/ouster/ouster_decoder.hpp"

#include <algorithm>
#include <array>
#include <cctype>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace rigcal::drivers {
namespace ouster {
namespace {

struct ModelId {
  int family = -1;  // 0, 1, 2
  int beams = 0;
};

/// "OS1-64", "OS-1-64", "OS-1-64-AH", "os1-64" → {1, 64}; {-1, 0} when it is not of that form.
ModelId parseModelName(const std::string& name) {
  std::string s;
  for (char c : name) s += char(std::toupper(static_cast<unsigned char>(c)));
  if (s.rfind("OS", 0) != 0) return {};
  std::size_t i = 2;
  if (i < s.size() && s[i] == '-') ++i;
  if (i >= s.size() || !std::isdigit(static_cast<unsigned char>(s[i]))) return {};
  ModelId id;
  id.family = s[i++] - '0';
  if (i >= s.size() || s[i] != '-') return {};
  ++i;
  int beams = 0, digits = 0;
  while (i < s.size() && std::isdigit(static_cast<unsigned char>(s[i])) && digits < 4) {
    beams = beams * 10 + (s[i++] - '0');
    ++digits;
  }
  if (digits == 0 || (i < s.size() && s[i] != '-')) return {};
  id.beams = beams;
  return id;
}

constexpr std::array<const char*, 10> kModels{"OS0-32", "OS0-64", "OS0-128", "OS1-16", "OS1-32",
                                              "OS1-64", "OS1-128", "OS2-32", "OS2-64", "OS2-128"};

}  // namespace

OusterDecoder::OusterDecoder(const DecoderConfig& config, Metadata metadata)
    : config_(config),
      md_(std::move(metadata)),
      format_(md_.profile, md_.pixels_per_column, md_.columns_per_packet),
      model_(config.model) {
  // Model ↔ metadata.
  const bool generic = config.model == "Ouster";
  const bool known = generic || std::find(kModels.begin(), kModels.end(), config.model) != kModels.end();
  if (!known) throw std::runtime_error("unknown Ouster model \"" + config.model + "\"");
  if (!generic && !md_.prod_line.empty()) {
    const ModelId want = parseModelName(config.model), have = parseModelName(md_.prod_line);
    if (have.family >= 0 && (have.family != want.family || have.beams != want.beams))
      throw std::runtime_error(md_.source + ": prod_line " + md_.prod_line + " does not match model " + config.model);
  }
  if (generic) {
    const ModelId have = parseModelName(md_.prod_line);
    model_ = have.family >= 0 ? "OS" + std::to_string(have.family) + "-" + std::to_string(have.beams)
                              : "OS-" + std::to_string(md_.pixels_per_column);
  }
  if (!(config.min_range_m >= 0) || !(config.max_range_m > config.min_range_m))
    throw std::runtime_error("Ouster decoder: bad range limits [" + std::to_string(config.min_range_m) + ", " +
                             std::to_string(config.max_range_m) + "] m");
  min_range_mm_ = std::uint32_t(std::ceil(double(config.min_range_m) * 1000.0));
  max_range_mm_ = std::uint32_t(std::min(double(config.max_range_m) * 1000.0, 4.0e9));

  // Ray table.
  const int w = md_.columns_per_frame, h = md_.pixels_per_column;
  const double b03 = md_.beam_to_lidar[3], b23 = md_.beam_to_lidar[11];
  const double n = b23 != 0 ? std::hypot(b03, b23) : b03;
  const auto& m = md_.lidar_to_sensor;
  rays_.resize(std::size_t(w) * std::size_t(h));
  constexpr double kPi = std::numbers::pi, kDeg = kPi / 180.0;
  for (int v = 0; v < w; ++v) {
    const double enc = 2.0 * kPi * (1.0 - double(v) / double(w));
    for (int u = 0; u < h; ++u) {
      const double az = -md_.beam_azimuth_deg[std::size_t(u)] * kDeg;
      const double alt = md_.beam_altitude_deg[std::size_t(u)] * kDeg;
      const double d[3] = {std::cos(enc + az) * std::cos(alt), std::sin(enc + az) * std::cos(alt), std::sin(alt)};
      const double o[3] = {std::cos(enc) * b03 - d[0] * n, std::sin(enc) * b03 - d[1] * n, b23 - d[2] * n};
      double ds[3], os[3];
      for (int r = 0; r < 3; ++r) {
        ds[r] = m[4 * r] * d[0] + m[4 * r + 1] * d[1] + m[4 * r + 2] * d[2];
        os[r] = m[4 * r] * o[0] + m[4 * r + 1] * o[1] + m[4 * r + 2] * o[2] + m[4 * r + 3];
      }
      double azimuth = std::atan2(ds[1], ds[0]) / kDeg;
      if (azimuth < 0) azimuth += 360.0;
      if (azimuth >= 360.0) azimuth -= 360.0;
      Ray& ray = rays_[std::size_t(v) * std::size_t(h) + std::size_t(u)];
      ray = Ray{float(ds[0] * 1e-3), float(ds[1] * 1e-3), float(ds[2] * 1e-3), float(os[0] * 1e-3),
                float(os[1] * 1e-3),  float(os[2] * 1e-3), float(azimuth),     0.f};
    }
  }

  // Packet slots the sensor sends, for loss accounting.
  const int slots = md_.packetSlots();
  window_prefix_.assign(std::size_t(slots) + 1, 0);
  for (int s = 0; s < slots; ++s) window_prefix_[std::size_t(s) + 1] = window_prefix_[std::size_t(s)] + (md_.slotInWindow(s) ? 1 : 0);
  column_period_ns_ = TimeNs(std::llround(1e9 / (double(w) * double(md_.frames_per_second))));
}

std::size_t OusterDecoder::maxPointsPerScan() const {
  return std::size_t(md_.columns_per_frame) * std::size_t(md_.pixels_per_column) * (format_.dual() ? 2 : 1);
}

std::uint64_t OusterDecoder::expectedBefore(std::uint64_t ordinal) const {
  const auto slots = std::uint64_t(md_.packetSlots());
  return (ordinal / slots) * std::uint64_t(window_prefix_.back()) + std::uint64_t(window_prefix_[ordinal % slots]);
}

void OusterDecoder::track(std::uint32_t frame_id, int slot, DecodedPacket& out) {
  const std::uint64_t modulus = format_.frameIdModulus();
  const auto slots = std::uint64_t(md_.packetSlots());
  // A jump of more than ~10 s of frames, or backwards by more than two frames, is a restart of the
  // sensor (or of its frame counter), not loss.
  const std::uint64_t max_forward = std::uint64_t(std::max(10 * md_.frames_per_second, 2));
  if (!have_last_) {
    have_last_ = true;
    frame_unwrapped_ = frame_id;
    last_frame_id_ = frame_id;
    last_ordinal_ = frame_unwrapped_ * slots + std::uint64_t(slot);
    out.order_key = last_ordinal_;
    return;
  }
  const std::uint64_t df = (std::uint64_t(frame_id) + modulus - last_frame_id_) % modulus;
  if (df >= modulus - 2) {  // a late packet of one of the previous two frames
    const std::uint64_t back = modulus - df;
    out.order_key = (frame_unwrapped_ >= back ? frame_unwrapped_ - back : 0) * slots + std::uint64_t(slot);
    return;
  }
  if (df > max_forward) {  // restart: continue the numbering without counting loss
    frame_unwrapped_ += 1;
    last_frame_id_ = frame_id;
    last_ordinal_ = frame_unwrapped_ * slots + std::uint64_t(slot);
    out.order_key = last_ordinal_;
    return;
  }
  const std::uint64_t ordinal = (frame_unwrapped_ + df) * slots + std::uint64_t(slot);
  out.order_key = ordinal;
  if (ordinal <= last_ordinal_) return;  // duplicate or reordered within the frame
  const std::uint64_t lost = expectedBefore(ordinal) - expectedBefore(last_ordinal_ + 1);
  out.lost_before = std::uint32_t(std::min<std::uint64_t>(lost, 0xffffffffu));
  frame_unwrapped_ += df;
  last_frame_id_ = frame_id;
  last_ordinal_ = ordinal;
}

template <UdpProfile P>
bool OusterDecoder::decodeColumns(const std::uint8_t* p, const UdpPacket& packet, DecodedPacket& out) {
  using L = PixelLayout<P>;
  const int h = md_.pixels_per_column, cpp = md_.columns_per_packet, w = md_.columns_per_frame;
  const bool host_time = config_.time_source == TimeSource::kHostReceive;
  const std::uint32_t min_mm = std::max<std::uint32_t>(min_range_mm_, 1), max_mm = max_range_mm_;
  const std::size_t header = format_.column_header_size;
  bool any_valid = false;
  for (int c = 0; c < cpp; ++c) {
    const std::uint8_t* col = format_.column(p, c);
    if (!PacketFormat::statusValid(format_.columnStatus(col))) continue;
    const int mid = PacketFormat::columnMeasurementId(col);
    if (mid >= w) {
      out.points.clear();
      out.azimuth_deg.clear();
      out.kind = DecodedPacket::Kind::kMalformed;
      out.error = "Ouster packet: column " + std::to_string(c) + " measurement_id " + std::to_string(mid) +
                  " >= columns_per_frame " + std::to_string(w);
      return false;
    }
    const TimeNs t = host_time ? packet.receive_ns - TimeNs(cpp - 1 - c) * column_period_ns_
                               : TimeNs(PacketFormat::columnTimestamp(col));
    if (!any_valid) {
      out.packet_time_ns = t;
      any_valid = true;
    }
    const Ray* rays = &rays_[std::size_t(mid) * std::size_t(h)];
    const std::uint8_t* px = col + header;
    for (int u = 0; u < h; ++u, px += L::kSize) {
      const Ray& ray = rays[u];
      const std::uint32_t r = L::range(px);
      if (r >= min_mm && r <= max_mm) {
        const float rf = float(r);
        out.points.push_back(Point{ray.dx * rf + ray.ox, ray.dy * rf + ray.oy, ray.dz * rf + ray.oz,
                                   float(L::reflectivity(px)), std::uint16_t(u), t, 0});
        out.azimuth_deg.push_back(ray.azimuth_deg);
      }
      if constexpr (L::kDual) {
        const std::uint32_t r2 = L::range2(px);
        if (r2 >= min_mm && r2 <= max_mm) {
          const float rf = float(r2);
          out.points.push_back(Point{ray.dx * rf + ray.ox, ray.dy * rf + ray.oy, ray.dz * rf + ray.oz,
                                     float(L::reflectivity2(px)), std::uint16_t(u), t, 1});
          out.azimuth_deg.push_back(ray.azimuth_deg);
        }
      }
    }
  }
  return any_valid;
}

void OusterDecoder::decode(const UdpPacket& packet, DecodedPacket& out) {
  out.reset();
  const std::size_t size = packet.payload.size();
  if (size != format_.packet_size) {
    if (size == kImuPacketSize) {
      out.kind = DecodedPacket::Kind::kIgnored;
      return;
    }
    out.kind = DecodedPacket::Kind::kMalformed;
    out.error = "Ouster " + std::string(toString(md_.profile)) + " packet: size " + std::to_string(size) +
                ", expected " + std::to_string(format_.packet_size);
    return;
  }
  const std::uint8_t* p = packet.payload.data();
  auto malformed = [&](std::string what) {
    out.kind = DecodedPacket::Kind::kMalformed;
    out.error = "Ouster packet: " + std::move(what);
  };
  if (!format_.legacy()) {
    if (const auto type = format_.packetType(p); type != 1)
      return malformed("packet_type " + std::to_string(type) + ", expected 1 (lidar)");
    if (const auto id = format_.initId(p); md_.init_id != 0 && id != 0 && id != md_.init_id)
      return malformed("init_id " + std::to_string(id) + " does not match the metadata's " + std::to_string(md_.init_id));
    if (const auto sn = format_.serial(p); md_.serial != 0 && sn != 0 && sn != md_.serial)
      return malformed("serial " + std::to_string(sn) + " does not match the metadata's " + std::to_string(md_.serial));
    if (md_.crcFooter() && crc64(p, size - 8) != format_.footerCrc(p)) return malformed("crc64 footer mismatch");
  }
  const int mid0 = PacketFormat::columnMeasurementId(format_.column(p, 0));
  if (mid0 >= md_.columns_per_frame)
    return malformed("measurement_id " + std::to_string(mid0) + " >= columns_per_frame " +
                     std::to_string(md_.columns_per_frame));

  const std::size_t max_points = std::size_t(format_.columns_per_packet) * std::size_t(md_.pixels_per_column) *
                                 (format_.dual() ? 2 : 1);
  if (out.points.capacity() < max_points) out.points.reserve(max_points);
  if (out.azimuth_deg.capacity() < max_points) out.azimuth_deg.reserve(max_points);

  bool any_valid = false;
  switch (md_.profile) {
    case UdpProfile::kLegacy: any_valid = decodeColumns<UdpProfile::kLegacy>(p, packet, out); break;
    case UdpProfile::kRng19Rfl8Sig16Nir16: any_valid = decodeColumns<UdpProfile::kRng19Rfl8Sig16Nir16>(p, packet, out); break;
    case UdpProfile::kRng19Rfl8Sig16Nir16Dual:
      any_valid = decodeColumns<UdpProfile::kRng19Rfl8Sig16Nir16Dual>(p, packet, out);
      break;
    case UdpProfile::kRng15Rfl8Nir8: any_valid = decodeColumns<UdpProfile::kRng15Rfl8Nir8>(p, packet, out); break;
    case UdpProfile::kFusaRng15Rfl8Nir8Dual:
      any_valid = decodeColumns<UdpProfile::kFusaRng15Rfl8Nir8Dual>(p, packet, out);
      break;
    case UdpProfile::kFiveWordPixel: any_valid = decodeColumns<UdpProfile::kFiveWordPixel>(p, packet, out); break;
  }
  if (out.kind == DecodedPacket::Kind::kMalformed) return;
  const std::uint32_t frame_id = format_.frameId(p);
  track(frame_id, mid0 / md_.columns_per_packet, out);
  if (!any_valid) {  // every column outside the window / invalid: a packet without data
    out.kind = DecodedPacket::Kind::kIgnored;
    return;
  }
  out.frame_id = frame_id;
}

}  // namespace ouster

std::unique_ptr<PacketDecoder> makeOusterDecoder(const DecoderConfig& config) {
  const auto models = ousterModels();
  if (std::find(models.begin(), models.end(), config.model) == models.end())
    throw std::runtime_error("unknown Ouster model \"" + config.model + "\"");
  if (config.metadata.empty())
    throw std::runtime_error("Ouster model " + config.model + " needs a metadata file (sensor_info JSON)");
  return std::make_unique<ouster::OusterDecoder>(config, ouster::parseMetadataFile(config.metadata));
}

std::vector<std::string> ousterModels() {
  std::vector<std::string> out(ouster::kModels.begin(), ouster::kModels.end());
  out.emplace_back("Ouster");
  return out;
}

}  // namespace rigcal::drivers
