#include "rigcal/drivers/scan_assembler.hpp"

#include <algorithm>
#include <cmath>

namespace rigcal::drivers {

ScanAssembler::ScanAssembler(std::string sensor_id, AssemblerConfig config, ScanCallback on_scan)
    : sensor_id_(std::move(sensor_id)), config_(config), on_scan_(std::move(on_scan)) {}

bool ScanAssembler::crossesCut(float from_deg, float to_deg) const {
  // Rotation is taken as forward; a step back of up to 90° is jitter (dual returns, interpolated
  // azimuths), not a full turn.
  const double step = std::fmod(double(to_deg) - from_deg + 720.0, 360.0);
  if (step == 0.0 || step > 270.0) return false;
  const double to_cut = std::fmod(config_.cut_angle_deg - from_deg + 720.0, 360.0);
  return to_cut > 0.0 && to_cut <= step;
}

void ScanAssembler::add(const DecodedPacket& packet) {
  ++stats_.packets;
  if (packet.kind == DecodedPacket::Kind::kMalformed) {
    ++stats_.malformed;
    stats_.last_error = packet.error;
    return;
  }
  if (packet.kind == DecodedPacket::Kind::kIgnored) {
    ++stats_.ignored;
    return;
  }
  stats_.lost_packets += packet.lost_before;

  if (last_packet_time_ && packet.packet_time_ns - *last_packet_time_ > config_.max_packet_gap_ns) {
    emit();
    last_azimuth_.reset();
  }
  last_packet_time_ = packet.packet_time_ns;

  if (packet.frame_id) {
    if (frame_id_ && *frame_id_ != *packet.frame_id) emit();
    frame_id_ = packet.frame_id;
    pending_lost_ += packet.lost_before;
    pending_.insert(pending_.end(), packet.points.begin(), packet.points.end());
    return;
  }

  pending_lost_ += packet.lost_before;
  for (std::size_t i = 0; i < packet.points.size(); ++i) {
    const float az = packet.azimuth_deg[i];
    if (last_azimuth_ && crossesCut(*last_azimuth_, az)) emit();
    last_azimuth_ = az;
    pending_.push_back(packet.points[i]);
  }
}

void ScanAssembler::flush() { emit(); }

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
