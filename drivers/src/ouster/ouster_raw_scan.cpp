#include "rigcal/drivers/ouster/ouster_raw_scan.hpp"

#include <algorithm>

namespace rigcal::drivers::ouster {

RawScan::RawScan(const Metadata& metadata)
    : format_(metadata.profile, metadata.pixels_per_column, metadata.columns_per_packet),
      w_(metadata.columns_per_frame),
      h_(metadata.pixels_per_column),
      shift_(metadata.pixel_shift_by_row) {
  shift_.resize(std::size_t(h_), 0);
  reset();
}

void RawScan::reset() {
  const std::size_t n = std::size_t(w_) * std::size_t(h_);
  range.assign(n, 0);
  range2.assign(n, 0);
  reflectivity.assign(n, 0);
  reflectivity2.assign(n, 0);
  signal.assign(n, 0);
  signal2.assign(n, 0);
  near_ir.assign(n, 0);
  timestamp.assign(std::size_t(w_), 0);
  status.assign(std::size_t(w_), 0);
  measurement_id.assign(std::size_t(w_), 0);
  frame_id_.reset();
  error_.clear();
  packets_ = 0;
}

RawScan::AddResult RawScan::add(std::span<const std::uint8_t> payload) {
  if (payload.size() != format_.packet_size) {
    error_ = "Ouster " + std::string(toString(format_.profile)) + " packet: size " + std::to_string(payload.size()) +
             ", expected " + std::to_string(format_.packet_size);
    return AddResult::kRejected;
  }
  const std::uint8_t* p = payload.data();
  if (!format_.legacy() && format_.packetType(p) != 1) {
    error_ = "Ouster packet: packet_type " + std::to_string(format_.packetType(p)) + ", expected 1 (lidar)";
    return AddResult::kRejected;
  }
  const std::uint32_t fid = format_.frameId(p);
  if (frame_id_ && *frame_id_ != fid) return AddResult::kOtherFrame;
  frame_id_ = fid;
  for (int c = 0; c < format_.columns_per_packet; ++c) {
    const std::uint8_t* col = format_.column(p, c);
    const int v = PacketFormat::columnMeasurementId(col);
    if (v >= w_) continue;  // out of this frame's bounds: dropped, as ouster-sdk does
    const auto vi = std::size_t(v);
    timestamp[vi] = PacketFormat::columnTimestamp(col);
    status[vi] = format_.columnStatus(col);
    measurement_id[vi] = std::uint16_t(v);
    for (int u = 0; u < h_; ++u) {
      const PixelFields f = format_.pixelFields(format_.pixel(col, u));
      const std::size_t i = std::size_t(u) * std::size_t(w_) + vi;
      range[i] = f.range;
      range2[i] = f.range2;
      reflectivity[i] = f.reflectivity;
      reflectivity2[i] = f.reflectivity2;
      signal[i] = f.signal;
      signal2[i] = f.signal2;
      near_ir[i] = f.near_ir;
    }
  }
  ++packets_;
  return AddResult::kAdded;
}

}  // namespace rigcal::drivers::ouster
