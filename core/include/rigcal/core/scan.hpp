#pragma once
// One full sweep of one lidar, as structure-of-arrays (the layout the registration and shm code want).
#include <cstddef>
#include <cstdint>
#include <string>
#include <vector>

#include "rigcal/core/time.hpp"

namespace rigcal {

/// One decoded return, the unit a decoder hands to the scan assembler.
struct Point {
  float x = 0, y = 0, z = 0;   // metres, sensor frame: x forward, y left, z up
  float intensity = 0;         // vendor reflectivity / intensity, unscaled
  std::uint16_t ring = 0;      // laser / channel / beam index
  TimeNs time_ns = 0;          // absolute time of the firing
  std::uint8_t return_index = 0;  // 0 = first/strongest/only, 1 = second return, ...
};

struct Scan {
  std::string sensor_id;
  std::uint64_t sequence = 0;
  TimeNs stamp_ns = 0;               // time of the earliest point
  std::uint32_t missing_packets = 0; // packets the assembler knows were lost inside this sweep

  std::vector<float> x, y, z;
  std::vector<float> intensity;
  std::vector<std::uint16_t> ring;
  std::vector<std::uint32_t> offset_ns;  // point time − stamp_ns (a sweep lasts well under 4 s)
  std::vector<std::uint8_t> return_index;

  [[nodiscard]] std::size_t size() const { return x.size(); }
  [[nodiscard]] bool empty() const { return x.empty(); }
  [[nodiscard]] TimeNs pointTime(std::size_t i) const { return stamp_ns + offset_ns[i]; }
  /// Time of the latest point (stamp_ns for an empty scan): points need not be in time order.
  [[nodiscard]] TimeNs endTime() const;

  void reserve(std::size_t n);
  /// Every array to n points (new points zeroed); within capacity it never allocates.
  void resize(std::size_t n);
  void clear();
  /// Appends a point; `time_ns` must be ≥ stamp_ns (the assembler sets stamp_ns first).
  void push_back(const Point& p);
  [[nodiscard]] Point point(std::size_t i) const;
  /// Keeps the points for which keep(i) is true, preserving order.
  template <class Pred>
  void filter(Pred keep);
};

template <class Pred>
void Scan::filter(Pred keep) {
  std::size_t out = 0;
  for (std::size_t i = 0; i < size(); ++i) {
    if (!keep(i)) continue;
    x[out] = x[i];
    y[out] = y[i];
    z[out] = z[i];
    intensity[out] = intensity[i];
    ring[out] = ring[i];
    offset_ns[out] = offset_ns[i];
    return_index[out] = return_index[i];
    ++out;
  }
  resize(out);
}

}  // namespace rigcal
