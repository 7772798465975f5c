#pragma once
// The simulated measurements of one sensor, firing sequence by firing sequence: what a packet encoder
// turns into vendor packets and what the sweep builder turns into SimulatedScans.
#include <cstdint>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "rigcal/core/time.hpp"

namespace rigcal::sim {

/// One beam's measurement in one firing sequence.
struct LaserReturn {
  float range_m = 0;     // reported range from the lidar origin, quantised to the model's distance unit
  float intensity = 0;   // 0..255, whole numbers (what an 8-bit reflectivity field carries)
  bool valid = false;    // false: no return (sky, out of range, dropout); range_m and intensity are 0
};

/// One firing sequence (every beam of the model fires once).
struct SimFiring {
  TimeNs sensor_time_ns = 0;     // sequence start on the sensor's clock (what packets carry)
  TimeNs true_time_ns = 0;       // the same instant on the reference clock (poses, pcap capture times)
  double rotor_azimuth_deg = 0;  // rotor azimuth at sequence start, [0, 360)
  std::int64_t sequence = 0;     // consecutive per sensor; a gap means the sensor was silent
  std::int64_t frame = 0;        // rotation count; increments where the rotor passes the frame start
  std::int32_t column = -1;      // Ouster: measurement id within the frame; −1 for other vendors
};

struct FiringBatch {
  std::size_t beams = 0;
  std::vector<SimFiring> firings;
  std::vector<LaserReturn> returns;    // returns[f·beams + b]
  std::vector<Eigen::Vector3f> points; // sensor-frame point a decoder recovers (valid returns only)

  [[nodiscard]] std::size_t size() const { return firings.size(); }
  [[nodiscard]] std::span<const LaserReturn> returnsOf(std::size_t f) const {
    return {returns.data() + f * beams, beams};
  }
  void clear() {
    firings.clear();
    returns.clear();
    points.clear();
  }
};

}  // namespace rigcal::sim
