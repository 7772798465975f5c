#pragma once
// The physics output without packets: one sweep of one sensor as a decoder would deliver it (sensor
// frame, sensor-clock stamps, beam index as ring), plus what only the simulator knows: each point's
// true time and, on request, the true sensor pose at that time. Tests use it to check the physics
// (skew, noise, scene hits) independently of the vendor encoders.
#include <cstdint>
#include <functional>
#include <optional>
#include <vector>

#include "rigcal/core/pose.hpp"
#include "rigcal/core/scan.hpp"
#include "rigcal/sim/firing.hpp"
#include "rigcal/sim/lidar_model.hpp"

namespace rigcal::sim {

struct SimulatedScan {
  std::size_t sensor = 0;          // index into the scenario's sensors
  std::int64_t frame = 0;          // rotation count of the sweep
  Scan scan;                       // sensor frame; stamp_ns / offset_ns on the sensor clock
  std::vector<TimeNs> true_time_ns;  // per point, reference clock
  std::vector<Pose> T_world_sensor;  // per point, when requested (else empty)
};

/// Cuts one sensor's firings into sweeps: a sweep ends where the frame number changes or the sensor
/// fell silent (a gap in the sequence numbers).
class SweepBuilder {
 public:
  using PoseAt = std::function<Pose(TimeNs true_time)>;
  using Emit = std::function<void(SimulatedScan&&)>;

  /// `truth` (optional) gives T_world_sensor per point; `emit` receives every finished sweep.
  SweepBuilder(std::size_t sensor, std::string sensor_id, const LidarModel& model, PoseAt truth, Emit emit);
  void add(const FiringBatch& batch);
  /// Emits the sweep in progress (the recording ended).
  void flush();

 private:
  void startSweep(const SimFiring& f);

  std::size_t sensor_;
  std::string sensor_id_;
  const LidarModel* model_;
  PoseAt truth_;
  Emit emit_;
  std::optional<SimulatedScan> current_;
  std::int64_t last_sequence_ = 0;
  std::uint64_t next_seq_ = 0;
};

}  // namespace rigcal::sim
