#include "rigcal/core/scan.hpp"

#include <algorithm>
#include <cassert>

namespace rigcal {

void Scan::reserve(std::size_t n) {
  x.reserve(n);
  y.reserve(n);
  z.reserve(n);
  intensity.reserve(n);
  ring.reserve(n);
  offset_ns.reserve(n);
  return_index.reserve(n);
}

void Scan::resize(std::size_t n) {
  x.resize(n);
  y.resize(n);
  z.resize(n);
  intensity.resize(n);
  ring.resize(n);
  offset_ns.resize(n);
  return_index.resize(n);
}

void Scan::clear() {
  x.clear();
  y.clear();
  z.clear();
  intensity.clear();
  ring.clear();
  offset_ns.clear();
  return_index.clear();
  missing_packets = 0;
}

void Scan::push_back(const Point& p) {
  assert(p.time_ns >= stamp_ns);
  x.push_back(p.x);
  y.push_back(p.y);
  z.push_back(p.z);
  intensity.push_back(p.intensity);
  ring.push_back(p.ring);
  offset_ns.push_back(static_cast<std::uint32_t>(p.time_ns - stamp_ns));
  return_index.push_back(p.return_index);
}

TimeNs Scan::endTime() const {
  std::uint32_t latest = 0;
  for (std::uint32_t o : offset_ns) latest = std::max(latest, o);
  return stamp_ns + TimeNs(latest);
}

Point Scan::point(std::size_t i) const {
  return Point{x[i], y[i], z[i], intensity[i], ring[i], pointTime(i), return_index[i]};
}

}  // namespace rigcal
