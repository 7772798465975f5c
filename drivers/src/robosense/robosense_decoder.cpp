#include "rigcal/drivers/robosense/robosense_decoder.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

namespace rigcal::drivers {
namespace {

using namespace robosense;

constexpr std::int32_t kAzimuthUnitsPerTurn = 36000;  // 0.01°
constexpr float kBlockUs = 55.56f;             // one block's firing period
constexpr std::int64_t kBlockNs = 55560;
constexpr float kLensOffsetM = 0.03498f;       // optical centre to rotation axis (rs_driver's RX)
// Firing offset of each of the 32 channel slots from the block start (µs), from nebula's Helios-16P decoder.
constexpr float kFiringUs[kChannelsPerBlock] = {
    0.00f,  3.15f,  6.30f,  9.45f,  13.26f, 17.08f, 20.56f, 23.71f, 26.53f, 27.77f, 31.49f,
    32.73f, 36.46f, 38.94f, 41.42f, 43.91f, 55.56f, 58.70f, 61.85f, 65.00f, 68.82f, 72.64f,
    76.12f, 79.27f, 82.08f, 83.32f, 87.05f, 88.29f, 92.01f, 94.50f, 96.98f, 99.46f};

struct Trig {
  std::vector<float> cos, sin;
  Trig() : cos(kAzimuthUnitsPerTurn), sin(kAzimuthUnitsPerTurn) {
    for (int a = 0; a < kAzimuthUnitsPerTurn; ++a) {
      const double rad = a * 0.01 * std::numbers::pi / 180.0;
      cos[std::size_t(a)] = float(std::cos(rad));
      sin[std::size_t(a)] = float(std::sin(rad));
    }
  }
  static std::size_t index(std::int32_t a) { return std::size_t(((a % kAzimuthUnitsPerTurn) + kAzimuthUnitsPerTurn) % kAzimuthUnitsPerTurn); }
};
const Trig& trig() {
  static const Trig t;
  return t;
}

}  // namespace

RobosenseDecoder::RobosenseDecoder(const DecoderConfig& config)
    : time_source_(config.time_source),
      min_range_m_(std::max(config.min_range_m, float(kSensorMinRangeM))),
      max_range_m_(std::min(config.max_range_m, float(kSensorMaxRangeM))) {
  if (config.model != "RS-Helios-16P")
    throw std::runtime_error("unknown RoboSense model '" + config.model + "' (known: RS-Helios-16P)");
  if (!config.calibration.empty())
    throw std::runtime_error("RS-Helios-16P reads its angles from the DIFOP packet (port 7788); calibration file '" +
                             config.calibration.string() + "' is not used: remove it");
  trig();
}

std::size_t RobosenseDecoder::maxPointsPerScan() const {
  // 32 slots per 55.56 µs block; the slowest rotation (300 rpm) takes 0.2 s per turn.
  return std::size_t(0.2 / 55.56e-6 + 1) * kChannelsPerBlock;
}

void RobosenseDecoder::applyDeviceInfo(const DeviceInfo& info) {
  info_ = info;
  dual_ = info.return_mode == ReturnMode::kDual;
  int rps = info.rpm / 60;  // whole turns per second, as the vendors' decoders
  if (rps == 0) rps = 10;
  scan_rate_hz_ = rps;
  block_az_diff_ = std::int32_t(std::lround(double(kAzimuthUnitsPerTurn) * rps * double(kBlockUs / 1e6f)));
  const int fov_range = info.fov_start < info.fov_end ? info.fov_end - info.fov_start
                                                      : info.fov_end + kAzimuthUnitsPerTurn - info.fov_start;
  fov_blind_ns_ = std::llround(double(kAzimuthUnitsPerTurn - fov_range) / (double(kAzimuthUnitsPerTurn) * rps) * 1e9);
  for (int c = 0; c < kChannelsPerBlock; ++c) {
    // Single return: 32 slots are two firings of the 16 lasers; dual: both returns of one firing.
    const float us = dual_ ? kFiringUs[c % kLasers] : kFiringUs[c];
    az_share_[std::size_t(c)] = dual_ ? us / kBlockUs : us / (kBlockUs * 2);
    chan_ns_[std::size_t(c)] = std::int32_t(std::lround(double(us) * 1000.0));
  }
  for (int l = 0; l < kLasers; ++l) {
    const double v = info.vertical[std::size_t(l)] * 0.01 * std::numbers::pi / 180.0;
    cos_vert_[std::size_t(l)] = float(std::cos(v));
    sin_vert_[std::size_t(l)] = float(std::sin(v));
    horiz_[std::size_t(l)] = info.horizontal[std::size_t(l)];
    // Ring: lasers numbered from the lowest beam up.
    std::uint16_t below = 0;
    for (int k = 0; k < kLasers; ++k)
      if (info.vertical[std::size_t(k)] < info.vertical[std::size_t(l)]) ++below;
    ring_[std::size_t(l)] = below;
  }
}

std::uint32_t RobosenseDecoder::lostBefore(std::uint32_t counter) {
  std::uint32_t lost = 0;
  if (last_counter_) {
    const std::uint32_t ahead = counter - *last_counter_;
    if (ahead > 1 && ahead <= (1u << 20)) lost = ahead - 1;
  }
  last_counter_ = counter;
  return lost;
}

std::uint64_t RobosenseDecoder::orderKey(const MsopView& view, TimeNs receive_ns) const {
  if (time_source_ == TimeSource::kHostReceive) return std::uint64_t(receive_ns);
  return view.seconds * 1'000'000 + view.microseconds;
}

TimeNs RobosenseDecoder::decodeMsop(const MsopView& view, TimeNs receive_ns, DecodedPacket& out) {
  const int group = dual_ ? 2 : 1;
  // Per block: the azimuth step to the next firing and the firing's time offset in the packet.
  std::int32_t az_diff[kBlocks];
  std::int64_t block_ns[kBlocks];
  std::int64_t t = 0;
  for (int b = 0; b < kBlocks; b += group) {
    std::int32_t diff = block_az_diff_;
    std::int64_t step = kBlockNs;
    if (b + group < kBlocks) {
      diff = (std::int32_t(view.azimuth(b + group)) - view.azimuth(b) + kAzimuthUnitsPerTurn) % kAzimuthUnitsPerTurn;
      if (diff > 100) {  // across the blind part of a limited FOV
        diff = block_az_diff_;
        step = fov_blind_ns_;
      }
    }
    for (int k = 0; k < group; ++k) {
      az_diff[b + k] = diff;
      block_ns[b + k] = t;
    }
    t += step;
  }
  const std::int64_t last_firing_ns = block_ns[kBlocks - 1] + *std::max_element(chan_ns_.begin(), chan_ns_.end());
  const TimeNs t0 = time_source_ == TimeSource::kHostReceive
                        ? receive_ns - last_firing_ns
                        : TimeNs(view.seconds) * kNsPerSec + TimeNs(view.microseconds) * kNsPerUs;

  const Trig& tr = trig();
  for (int b = 0; b < kBlocks; ++b) {
    const std::int32_t block_az = view.azimuth(b);
    const float block_deg = float(block_az) * 0.01f;
    const std::uint8_t* ch = view.channels(b);
    for (int c = 0; c < kChannelsPerBlock; ++c) {
      const std::uint8_t* u = ch + 3 * c;
      const std::uint32_t raw = std::uint32_t(u[0]) << 8 | u[1];
      if (raw == 0) continue;
      const float d = float(raw) * float(kDistanceUnitM);
      if (d < min_range_m_ || d > max_range_m_) continue;
      const int laser = c % kLasers;
      const std::int32_t az = block_az + std::int32_t(float(az_diff[b]) * az_share_[std::size_t(c)]);
      const std::size_t fin = Trig::index(az + horiz_[std::size_t(laser)]);
      const std::size_t rot = Trig::index(az);
      const float xy = d * cos_vert_[std::size_t(laser)];
      Point p;
      p.x = xy * tr.cos[fin] + kLensOffsetM * tr.cos[rot];
      p.y = -xy * tr.sin[fin] - kLensOffsetM * tr.sin[rot];
      p.z = d * sin_vert_[std::size_t(laser)];
      p.intensity = u[2];
      p.ring = ring_[std::size_t(laser)];
      p.time_ns = t0 + block_ns[b] + chan_ns_[std::size_t(c)];
      p.return_index = std::uint8_t(dual_ && c >= kLasers ? 1 : 0);
      out.points.push_back(p);
      out.azimuth_deg.push_back(block_deg);
    }
  }
  return t0;
}

void RobosenseDecoder::decode(const UdpPacket& packet, DecodedPacket& out) {
  out.reset();
  if (isDifop(packet.payload)) {
    DeviceInfo info;
    if (std::string error = parseDifop(packet.payload, info); !error.empty()) {
      out.kind = DecodedPacket::Kind::kMalformed;
      out.error = std::move(error);
      return;
    }
    ++stats_.difop_packets;
    const bool first = !info_;
    applyDeviceInfo(info);
    out.kind = DecodedPacket::Kind::kIgnored;
    out.packet_time_ns = packet.receive_ns;
    if (!first || held_.empty()) return;
    // The angles are known now: decode the packets that waited for them, as one batch.
    out.kind = DecodedPacket::Kind::kData;
    for (const Held& h : held_) {
      MsopView view;
      parseMsop(h.payload, view);  // checked when held
      out.lost_before += lostBefore(view.counter);
      out.packet_time_ns = decodeMsop(view, h.receive_ns, out);
      out.order_key = orderKey(view, h.receive_ns);
    }
    held_.clear();
    return;
  }
  MsopView view;
  if (std::string error = parseMsop(packet.payload, view); !error.empty()) {
    out.kind = DecodedPacket::Kind::kMalformed;
    out.error = std::move(error);
    return;
  }
  if (!info_) {
    if (held_.size() == kMaxHeldPackets) {
      held_.pop_front();
      ++stats_.dropped_without_difop;
    }
    held_.push_back({std::vector<std::uint8_t>(packet.payload.begin(), packet.payload.end()), packet.receive_ns});
    ++stats_.held_for_difop;
    out.kind = DecodedPacket::Kind::kIgnored;
    out.packet_time_ns = packet.receive_ns;
    return;
  }
  out.kind = DecodedPacket::Kind::kData;
  out.lost_before = lostBefore(view.counter);
  out.packet_time_ns = decodeMsop(view, packet.receive_ns, out);
  out.order_key = orderKey(view, packet.receive_ns);
}

void RobosenseDecoder::flush(DecodedPacket& out) {
  out.reset();
  stats_.dropped_without_difop += held_.size();
  held_.clear();
}

std::unique_ptr<PacketDecoder> makeRobosenseDecoder(const DecoderConfig& config) {
  return std::make_unique<RobosenseDecoder>(config);
}

std::vector<std::string> robosenseModels() { return {"RS-Helios-16P"}; }

}  // namespace rigcal::drivers
