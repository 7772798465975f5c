#pragma once
// When a sensor fires: a fixed grid of firing sequences on the sensor's own clock, its rotor
// phase-locked so that the azimuth at every whole second of sensor time is the sensor's scan phase.
// The clock offset maps true time to sensor time (sensor = true + offset).
#include <vector>

#include "rigcal/sim/firing.hpp"
#include "rigcal/sim/lidar_model.hpp"

namespace rigcal::sim {

class FiringScheduler {
 public:
  /// `start_true_ns`: the earliest true time that will be scheduled (anchors the firing grid).
  FiringScheduler(const LidarModel& model, double scan_phase_deg, TimeNs clock_offset_ns, TimeNs start_true_ns);

  /// Appends the sequences that start in [from_true, to_true) (true clock), in order.
  void schedule(TimeNs from_true, TimeNs to_true, std::vector<SimFiring>& out) const;

  [[nodiscard]] double rotorAzimuthDeg(TimeNs sensor_time) const;
  /// Rotation count at a sensor time: increments as the rotor passes frame_start_azimuth.
  [[nodiscard]] std::int64_t frameIndex(TimeNs sensor_time) const;
  [[nodiscard]] TimeNs sensorTime(std::int64_t sequence) const;
  [[nodiscard]] TimeNs clockOffset() const { return offset_; }

 private:
  [[nodiscard]] std::int64_t firstSequenceAtOrAfter(TimeNs sensor_time) const;

  const LidarModel* model_;
  double phase_deg_;
  TimeNs offset_;
  TimeNs frame_ns_;
  TimeNs frame_start_offset_ns_;  // within each frame period, when the rotor is at the frame start
  TimeNs anchor_ns_;              // sensor time of sequence 0: a frame start before the first firing
};

}  // namespace rigcal::sim
