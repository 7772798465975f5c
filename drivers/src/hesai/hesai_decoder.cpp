#include "rigcal/drivers/hesai/hesai_decoder.hpp"
#include "rigcal/drivers/hesai/hesai_firing_times.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <numeric>
#include <stdexcept>

namespace rigcal::drivers {
namespace {

constexpr std::int64_t kUnitsPerTurn = 36000;           // block azimuth unit: 0.01°
constexpr std::int64_t kMicroDegPerUnit = 10000;
constexpr std::int64_t kAzimuthBase = kUnitsPerTurn * 4096;  // keeps unwrapped azimuths positive
constexpr std::int64_t kLateToleranceUnits = 500;       // a backward step up to 5° is a late packet
constexpr std::uint32_t kMaxCountedGap = 1u << 20;      // larger sequence jumps: a sensor restart
constexpr std::uint32_t kMaxReorder = 4096;             // sequence steps back further: a restart
constexpr double kDualReturnThresholdM = 0.1;

std::int64_t floorDiv(std::int64_t a, std::int64_t b) {
  const std::int64_t q = a / b;
  return (a % b != 0 && ((a < 0) != (b < 0))) ? q - 1 : q;
}

// cos/sin of every block azimuth (0.01° steps), shared by all decoders.
struct AzimuthTable {
  std::vector<float> cos, sin;
  AzimuthTable() : cos(kUnitsPerTurn), sin(kUnitsPerTurn) {
    for (std::int64_t a = 0; a < kUnitsPerTurn; ++a) {
      const double rad = static_cast<double>(a) * 0.01 * std::numbers::pi / 180.0;
      cos[a] = static_cast<float>(std::cos(rad));
      sin[a] = static_cast<float>(std::sin(rad));
    }
  }
};
const AzimuthTable& azimuthTable() {
  static const AzimuthTable table;
  return table;
}

const hesai::ModelSpec& requireModel(const std::string& name) {
  if (const hesai::ModelSpec* spec = hesai::findModel(name)) return *spec;
  std::string known;
  for (const auto& m : hesai::allModels()) known += (known.empty() ? "" : ", ") + std::string(m.name);
  throw std::runtime_error("unknown Hesai model '" + name + "' (known: " + known + ")");
}

hesai::Calibration loadCalibration(const hesai::ModelSpec& spec, const DecoderConfig& config) {
  if (config.calibration.empty()) return hesai::nominalCalibration(spec);
  return hesai::readCalibrationCsv(config.calibration, spec.channels);
}

}  // namespace

HesaiDecoder::HesaiDecoder(const DecoderConfig& config)
    : HesaiDecoder(requireModel(config.model), loadCalibration(requireModel(config.model), config), config) {}

HesaiDecoder::HesaiDecoder(const hesai::ModelSpec& spec, const hesai::Calibration& cal, const DecoderConfig& config)
    : spec_(spec),
      time_source_(config.time_source),
      min_range_m_(std::max<double>(config.min_range_m, spec.min_range_m)),
      max_range_m_(std::min<double>(config.max_range_m, spec.max_range_m)),
      channels_(spec.channels) {
  if (cal.channels() != spec.channels)
    throw std::runtime_error(std::string(spec.name) + ": calibration has " + std::to_string(cal.channels()) +
                             " channels, expected " + std::to_string(spec.channels));

  // Channels sorted by azimuth offset: within one firing, points then come out in azimuth order.
  std::vector<std::int64_t> offset_udeg(channels_);
  for (int c = 0; c < channels_; ++c) offset_udeg[c] = std::llround(cal.azimuth_offset_deg[c] * 1e6);
  order_.resize(channels_);
  std::iota(order_.begin(), order_.end(), 0);
  std::stable_sort(order_.begin(), order_.end(),
                   [&](std::uint16_t a, std::uint16_t b) { return offset_udeg[a] < offset_udeg[b]; });
  for (std::uint16_t c : order_) {
    // Bucket b holds corrected azimuths in (b, b + 1] × 0.01°.
    shift_.push_back(floorDiv(offset_udeg[c] - 1, kMicroDegPerUnit));
    const double elevation = cal.elevation_deg[c] * std::numbers::pi / 180.0;
    const double offset = cal.azimuth_offset_deg[c] * std::numbers::pi / 180.0;
    xy_cos_.push_back(static_cast<float>(std::cos(elevation) * std::cos(offset)));
    xy_sin_.push_back(static_cast<float>(std::cos(elevation) * std::sin(offset)));
    z_sin_.push_back(static_cast<float>(std::sin(elevation)));
  }
  min_shift_ = shift_.front();

  cos_az_ = azimuthTable().cos.data();
  sin_az_ = azimuthTable().sin.data();

  for (int v = 0; v < kVariants; ++v) {
    const int returns = v == 0 ? 1 : 2;
    const std::uint8_t flag = v == 2 ? 1 : 0;
    auto& t = times_[v];
    t.resize(std::size_t(spec.blocks) * channels_);
    bool any = false;
    for (int b = 0; b < spec.blocks; ++b)
      for (int c = 0; c < channels_; ++c) {
        const auto ns = static_cast<std::int32_t>(hesai::firingOffsetNs(spec.model, returns, b, c, flag));
        t[std::size_t(b) * channels_ + c] = ns;
        // QT128 channels outside the block's firing sequence carry no data: not a firing.
        const int loop = returns == 1 ? b + 1 : (flag ? 1 : 2);
        if (spec.model == hesai::Model::kQT128 && hesai::qt128LoopOffsetNs(loop, c) == 0) continue;
        first_firing_ns_[v] = any ? std::min(first_firing_ns_[v], ns) : ns;
        last_firing_ns_[v] = any ? std::max(last_firing_ns_[v], ns) : ns;
        any = true;
      }
  }
}

std::uint64_t HesaiDecoder::orderKey(const hesai::PacketView& view, TimeNs t0, std::uint32_t& lost) {
  lost = 0;
  if (!view.udp_sequence) return static_cast<std::uint64_t>(t0);
  const std::uint32_t seq = *view.udp_sequence;
  if (!last_sequence_) {
    last_sequence_ = seq;
    return (sequence_epoch_ << 32) | seq;
  }
  const std::uint32_t last = *last_sequence_;
  const std::uint32_t ahead = seq - last;  // modulo 2^32
  const std::uint64_t last_key = (sequence_epoch_ << 32) | last;
  if (ahead == 0) return last_key;  // a duplicate
  if (ahead < 0x80000000u) {
    if (ahead - 1 <= kMaxCountedGap) lost = ahead - 1;
    if (seq < last) ++sequence_epoch_;
    last_sequence_ = seq;
    return last_key + ahead;
  }
  const std::uint32_t behind = last - seq;
  if (behind <= kMaxReorder && last_key >= behind) return last_key - behind;  // reordered: the assembler sorts
  // The sequence restarted (sensor reboot): continue from here without counting a loss.
  last_sequence_ = seq;
  ++sequence_epoch_;
  return (sequence_epoch_ << 32) | seq;
}

void HesaiDecoder::decode(const UdpPacket& packet, DecodedPacket& out) {
  out.reset();
  if (hesai::isGpsPacket(packet.payload)) {
    out.kind = DecodedPacket::Kind::kIgnored;
    out.packet_time_ns = packet.receive_ns;
    return;
  }
  hesai::PacketView view;
  if (std::string error = hesai::parsePacket(spec_, packet.payload, view); !error.empty()) {
    out.kind = DecodedPacket::Kind::kMalformed;
    out.error = std::move(error);
    return;
  }
  const int v = variant(view.returns, view.mode_flag);

  TimeNs t0 = 0;
  if (time_source_ == TimeSource::kSensorClock) {
    if (view.date != cached_date_ || cached_seconds_ < 0) {
      const auto seconds = hesai::utcSeconds(view.date, hesai::yearBase(spec_, view.date[0]));
      if (!seconds) {
        out.kind = DecodedPacket::Kind::kMalformed;
        out.error = std::string(spec_.name) + " packet: date field " +
                    std::to_string(hesai::yearBase(spec_, view.date[0]) + view.date[0]) + "-" +
                    std::to_string(view.date[1]) + "-" + std::to_string(view.date[2]) + " " +
                    std::to_string(view.date[3]) + ":" + std::to_string(view.date[4]) + ":" +
                    std::to_string(view.date[5]) + " is not a valid UTC time";
        return;
      }
      cached_date_ = view.date;
      cached_seconds_ = *seconds;
    }
    t0 = cached_seconds_ * kNsPerSec + TimeNs(view.timestamp_us) * kNsPerUs;
  } else {
    t0 = packet.receive_ns - last_firing_ns_[v];
  }
  if (view.has_crc && !view.crc_ok) ++stats_.crc_errors;
  if (view.motor_rpm >= 60 && view.motor_rpm <= 1500) scan_rate_hz_ = view.motor_rpm / 60.0;

  out.kind = DecodedPacket::Kind::kData;
  out.packet_time_ns = t0 + first_firing_ns_[v];
  out.order_key = orderKey(view, t0, out.lost_before);

  const RawLimits& limits = rawLimits(view.dis_unit_mm);
  std::optional<std::int64_t> release_up_to;
  for (int b = 0; b < view.blocks; b += view.returns) {
    const std::int64_t az = view.azimuth(b);
    std::int64_t unwrapped = kAzimuthBase + az;
    bool in_order = true;
    if (last_azimuth_) {
      const std::int64_t last = *last_azimuth_;
      const std::int64_t ahead = ((az - last % kUnitsPerTurn) % kUnitsPerTurn + kUnitsPerTurn) % kUnitsPerTurn;
      if (ahead != 0 && ahead <= kUnitsPerTurn / 2) {
        unwrapped = last + ahead;
      } else if (ahead == 0 || kUnitsPerTurn - ahead <= kLateToleranceUnits) {
        unwrapped = last - (ahead == 0 ? 0 : kUnitsPerTurn - ahead);
        in_order = false;
        ++stats_.late_firings;
      } else {
        // A jump backwards: start the azimuth ordering afresh from here.
        ++stats_.discontinuities;
        order_buffer_.releaseAll(out);
        unwrapped = last + ahead;
      }
    }
    const std::int32_t* times = times_[v].data() + std::size_t(b) * channels_;
    if (view.returns == 2) {
      decodeGroup<2>(view, b, unwrapped, t0, times, limits);
    } else {
      decodeGroup<1>(view, b, unwrapped, t0, times, limits);
    }
    if (in_order) {
      last_azimuth_ = unwrapped;
      release_up_to = unwrapped + min_shift_;
    }
  }
  if (release_up_to) {
    order_buffer_.release(*release_up_to, out);
  } else if (last_azimuth_) {
    order_buffer_.release(*last_azimuth_ + min_shift_, out);  // only late firings: pass them on
  }
}

const HesaiDecoder::RawLimits& HesaiDecoder::rawLimits(std::uint8_t dis_unit_mm) {
  RawLimits& l = raw_limits_[dis_unit_mm];
  if (l.unit_mm == dis_unit_mm) return l;
  // The float distance is monotonic in the raw value: find the raw interval whose distance passes
  // the range filter, and the raw differences that certainly are (not) within the dual threshold.
  const double scale = dis_unit_mm / 1000.0;
  auto distance = [&](std::uint32_t raw) { return static_cast<float>(raw * scale); };
  l.min_raw = 1;
  while (l.min_raw <= 0xFFFF && distance(l.min_raw) < min_range_m_) ++l.min_raw;
  l.max_raw = 0xFFFF;
  while (l.max_raw >= l.min_raw && distance(l.max_raw) > max_range_m_) --l.max_raw;
  // Raw differences up to `near_raw` are within 0.1 m whatever the float rounding (its error stays
  // below 0.1 mm up to 262 m); from `far_raw` on they never are; in between float decides.
  l.near_raw = static_cast<std::uint32_t>(std::floor((kDualReturnThresholdM - 1e-4) / scale));
  l.far_raw = static_cast<std::uint32_t>(std::ceil((kDualReturnThresholdM + 1e-4) / scale));
  l.scale = scale;
  l.unit_mm = dis_unit_mm;
  return l;
}

template <int kReturns>
void HesaiDecoder::decodeGroup(const hesai::PacketView& view, int first_block, std::int64_t unwrapped, TimeNs t0,
                               const std::int32_t* times, const RawLimits& limits) {
  const std::size_t az_index = static_cast<std::size_t>(unwrapped % kUnitsPerTurn);
  const float ca = cos_az_[az_index], sa = sin_az_[az_index];
  const float scale = static_cast<float>(limits.scale);
  const std::uint8_t* blocks[2] = {view.units(first_block), view.units(first_block + kReturns - 1)};
  const std::size_t stride = view.unit_bytes;
  for (int j = 0; j < channels_; ++j) {
    const int c = order_[j];
    std::uint32_t raw[kReturns];
    std::uint32_t any = 0;
    for (int k = 0; k < kReturns; ++k) {
      const std::uint8_t* u = blocks[k] + stride * c;
      raw[k] = static_cast<std::uint32_t>(u[0] | (u[1] << 8));
      any |= raw[k];
    }
    if (any == 0) continue;  // no return, or a channel outside this firing sequence
    for (int k = 0; k < kReturns; ++k) {
      if (raw[k] < limits.min_raw || raw[k] > limits.max_raw) continue;  // also drops raw 0
      if (k + 1 < kReturns) {
        // Dual return: keep the last; drop the other when it is within 0.1 m of it (computed in
        // float, as nebula does, when the difference sits right on the threshold).
        const std::uint32_t diff = raw[k] > raw[k + 1] ? raw[k] - raw[k + 1] : raw[k + 1] - raw[k];
        if (diff <= limits.near_raw) continue;
        if (diff < limits.far_raw &&
            std::fabs(static_cast<float>(raw[k + 1] * limits.scale) - static_cast<float>(raw[k] * limits.scale)) <
                kDualReturnThresholdM)
          continue;
      }
      const float d = static_cast<float>(raw[k]) * scale;
      const float cx = xy_cos_[j], sx = xy_sin_[j];
      Point& p = order_buffer_.emplace(unwrapped + shift_[j]);
      p.x = d * (cx * ca - sx * sa);
      p.y = -d * (cx * sa + sx * ca);
      p.z = d * z_sin_[j];
      p.intensity = blocks[k][stride * c + 2];
      p.ring = static_cast<std::uint16_t>(c);
      p.time_ns = t0 + times[c];
      p.return_index = static_cast<std::uint8_t>(k);
    }
  }
  order_buffer_.endRun();
}

void HesaiDecoder::flush(DecodedPacket& out) {
  out.reset();
  out.kind = DecodedPacket::Kind::kData;
  order_buffer_.releaseAll(out);
  if (!out.points.empty()) {
    out.packet_time_ns = std::min_element(out.points.begin(), out.points.end(), [](const Point& a, const Point& b) {
                           return a.time_ns < b.time_ns;
                         })->time_ns;
  }
  if (last_sequence_) out.order_key = ((sequence_epoch_ << 32) | *last_sequence_) + 1;
  last_azimuth_.reset();
}

std::unique_ptr<PacketDecoder> makeHesaiDecoder(const DecoderConfig& config) {
  return std::make_unique<HesaiDecoder>(config);
}

std::vector<std::string> hesaiModels() {
  std::vector<std::string> names;
  for (const auto& m : hesai::allModels()) names.emplace_back(m.name);
  return names;
}

}  // namespace rigcal::drivers
