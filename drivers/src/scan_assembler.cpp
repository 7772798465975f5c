#include "rigcal/drivers/scan_assembler.hpp"

#include <algorithm>
#include <cmath>

namespace rigcal::drivers {

ScanAssembler::ScanAssembler(std::string sensor_id, AssemblerConfig config, ScanCallback on_scan)
    : sensor_id_(std::move(sensor_id)), config_(config), on_scan_(std::move(on_scan)) {
  if (config_.reorder_window > 0) {
    // One slot more than the window: a new packet is inserted before the oldest is released.
    slots_.resize(config_.reorder_window + 1);
    window_.reserve(slots_.size());
    free_.reserve(slots_.size());
    for (std::size_t i = slots_.size(); i-- > 0;) free_.push_back(i);
  }
}

bool ScanAssembler::crossesCut(float from_deg, float to_deg) const {
  // Rotation is taken as forward; a step back of up to 90° is jitter (dual returns, interpolated
  // azimuths), not a full turn.
  const double step = std::fmod(double(to_deg) - from_deg + 720.0, 360.0);
  if (step == 0.0 || step > 270.0) return false;
  const double to_cut = std::fmod(config_.cut_angle_deg - from_deg + 720.0, 360.0);
  return to_cut > 0.0 && to_cut <= step;
}

bool ScanAssembler::admit(const DecodedPacket& packet) {
  ++stats_.packets;
  if (packet.kind == DecodedPacket::Kind::kMalformed) {
    ++stats_.malformed;
    stats_.last_error = packet.error;
    return false;
  }
  if (packet.kind == DecodedPacket::Kind::kIgnored) {
    ++stats_.ignored;
    return false;
  }
  if (config_.reorder_window > 0 && released_key_ && packet.order_key < *released_key_) {
    if (++consecutive_late_ <= config_.reorder_window) {
      ++stats_.late_dropped;  // too late to put in its place: the sweep it belongs to moved on
      return false;
    }
    // More late packets in a row than the window holds: the key went back for good (sensor restart,
    // counter wrap). Release what is held and start ordering afresh from this packet.
    ++stats_.key_resets;
    while (!window_.empty()) releaseOldest();
    released_key_.reset();
    max_key_.reset();
  }
  consecutive_late_ = 0;
  if (max_key_ && packet.order_key < *max_key_) ++stats_.reordered;
  if (!max_key_ || packet.order_key > *max_key_) max_key_ = packet.order_key;
  return true;
}

void ScanAssembler::add(const DecodedPacket& packet) {
  if (!admit(packet)) return;
  if (config_.reorder_window == 0) return process(packet);
  const std::size_t slot = free_.back();
  free_.pop_back();
  slots_[slot] = packet;  // copy-assignment reuses the slot's capacity
  hold(slot);
}

void ScanAssembler::add(DecodedPacket&& packet) {
  if (!admit(packet)) return;
  if (config_.reorder_window == 0) return process(packet);
  const std::size_t slot = free_.back();
  free_.pop_back();
  std::swap(slots_[slot], packet);  // the caller gets the slot's old buffers back
  hold(slot);
}

void ScanAssembler::hold(std::size_t slot) {
  const std::uint64_t key = slots_[slot].order_key;
  // Stable: a packet goes after held ones with an equal key (decoders without a key use 0).
  const auto at = std::upper_bound(window_.begin(), window_.end(), key,
                                   [&](std::uint64_t k, std::size_t s) { return k < slots_[s].order_key; });
  window_.insert(at, slot);
  if (window_.size() > config_.reorder_window) releaseOldest();
}

void ScanAssembler::releaseOldest() {
  const std::size_t slot = window_.front();
  window_.erase(window_.begin());
  released_key_ = slots_[slot].order_key;
  process(slots_[slot]);
  free_.push_back(slot);
}

void ScanAssembler::process(const DecodedPacket& packet) {
  stats_.lost_packets += packet.lost_before;

  if (last_packet_time_ && packet.packet_time_ns - *last_packet_time_ > config_.max_packet_gap_ns) {
    emit();
    last_azimuth_.reset();
  }
  last_packet_time_ = packet.packet_time_ns;

  if (packet.frame_id) {
    if (frame_id_ && *frame_id_ != *packet.frame_id) emit();
    noteLag(packet);
    frame_id_ = packet.frame_id;
    pending_lost_ += packet.lost_before;
    pending_.insert(pending_.end(), packet.points.begin(), packet.points.end());
    return;
  }

  pending_lost_ += packet.lost_before;
  noteLag(packet);  // before the cut below: this packet ends the sweep it emits
  for (std::size_t i = 0; i < packet.points.size(); ++i) {
    const float az = packet.azimuth_deg[i];
    if (last_azimuth_ && crossesCut(*last_azimuth_, az)) emit();
    last_azimuth_ = az;
    pending_.push_back(packet.points[i]);
  }
}

void ScanAssembler::noteLag(const DecodedPacket& packet) {
  if (packet.receive_ns == 0 || packet.points.empty()) return;
  const auto last = std::max_element(packet.points.begin(), packet.points.end(),
                                     [](const Point& a, const Point& b) { return a.time_ns < b.time_ns; });
  last_packet_lag_ns_ = packet.receive_ns - last->time_ns;
}

void ScanAssembler::flush() {
  while (!window_.empty()) releaseOldest();
  emit();
  released_key_.reset();  // input may start again (a replay loop): order it afresh
  max_key_.reset();
  consecutive_late_ = 0;
}

void ScanAssembler::emit() {
  if (pending_.size() >= std::max<std::size_t>(config_.min_points, 1)) {
    Scan scan;
    scan.sensor_id = sensor_id_;
    scan.sequence = sequence_++;
    scan.missing_packets = pending_lost_;
    scan.stamp_ns = std::min_element(pending_.begin(), pending_.end(), [](const Point& a, const Point& b) {
                      return a.time_ns < b.time_ns;
                    })->time_ns;
    scan.reserve(pending_.size());
    for (const Point& p : pending_) scan.push_back(p);
    ++stats_.scans;
    on_scan_(std::move(scan));
  }
  pending_.clear();
  pending_lost_ = 0;
}

}  // namespace rigcal::drivers
