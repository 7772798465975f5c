#pragma once
// Cuts the stream of decoded packets into full sweeps. A sweep ends where the sensor's own frame id
// changes (Ouster), or else where the rotor azimuth crosses the cut angle (Velodyne, Hesai). Sweeps
// that straddle packets are handled point by point; a gap in time also ends a sweep.
#include <cstdint>
#include <functional>
#include <optional>
#include <string>
#include <vector>

#include "rigcal/core/scan.hpp"
#include "rigcal/drivers/packet_decoder.hpp"

namespace rigcal::drivers {

struct AssemblerConfig {
  double cut_angle_deg = 0.0;           // azimuth at which a sweep starts, in [0, 360)
  TimeNs max_packet_gap_ns = 200 * kNsPerMs;  // a silence this long ends the sweep in progress
  std::size_t min_points = 1;           // shorter sweeps (e.g. empty) are not emitted
};

struct AssemblerStats {
  std::uint64_t packets = 0;
  std::uint64_t malformed = 0;
  std::uint64_t ignored = 0;
  std::uint64_t lost_packets = 0;
  std::uint64_t scans = 0;
  std::string last_error;               // the latest malformed packet's reason
};

class ScanAssembler {
 public:
  using ScanCallback = std::function<void(Scan&&)>;

  ScanAssembler(std::string sensor_id, AssemblerConfig config, ScanCallback on_scan);

  /// Feeds one decoded packet; completed sweeps are passed to the callback, in order.
  void add(const DecodedPacket& packet);
  /// End of input: emits the sweep in progress (a partial sweep is still a sweep).
  void flush();
  [[nodiscard]] const AssemblerStats& stats() const { return stats_; }

 private:
  [[nodiscard]] bool crossesCut(float from_deg, float to_deg) const;
  void emit();

  std::string sensor_id_;
  AssemblerConfig config_;
  ScanCallback on_scan_;
  AssemblerStats stats_;

  std::vector<Point> pending_;
  std::uint32_t pending_lost_ = 0;
  std::optional<float> last_azimuth_;
  std::optional<std::uint64_t> frame_id_;
  std::optional<TimeNs> last_packet_time_;
  std::uint64_t sequence_ = 0;
};

}  // namespace rigcal::drivers
