#include "scan_pattern.hpp"

#include <cstring>

namespace rigcal::shm::test {

namespace {

std::uint64_t mix(std::uint64_t v) {  // splitmix64 finaliser
  v += 0x9e3779b97f4a7c15ULL;
  v = (v ^ (v >> 30)) * 0xbf58476d1ce4e5b9ULL;
  v = (v ^ (v >> 27)) * 0x94d049bb133111ebULL;
  return v ^ (v >> 31);
}

struct Values {
  float x, y, z, intensity;
  std::uint16_t ring;
  std::uint32_t offset_ns;
  std::uint8_t return_index;
};

Values valuesAt(std::uint64_t sequence, std::uint32_t i) {
  const std::uint64_t h = mix((sequence << 32) ^ i);
  Values v;
  v.x = static_cast<float>(static_cast<std::int32_t>(h & 0xfffff) - 0x80000) * 1e-3f;
  v.y = static_cast<float>((h >> 20) & 0xfffff) * 1e-3f;
  v.z = static_cast<float>((h >> 40) & 0xffff) * 1e-3f;
  v.intensity = static_cast<float>(i % 256);
  v.ring = static_cast<std::uint16_t>(h >> 48);
  v.offset_ns = static_cast<std::uint32_t>(h) ^ static_cast<std::uint32_t>(sequence);
  v.return_index = static_cast<std::uint8_t>(h >> 56);
  return v;
}

bool same(float a, float b) { return std::memcmp(&a, &b, sizeof a) == 0; }

}  // namespace

std::uint32_t patternPoints(std::uint64_t sequence, std::uint32_t max_points) {
  const std::uint64_t shrink = (sequence % 5) * max_points / 10;  // 0, 10, 20, 30, 40 %
  return static_cast<std::uint32_t>(max_points - shrink);
}

void fillPattern(Scan& scan, std::uint64_t sequence, std::uint32_t points) {
  scan.sequence = sequence;
  scan.stamp_ns = 1'600'000'000'000'000'000 + static_cast<std::int64_t>(sequence) * 100'000'000;
  scan.missing_packets = static_cast<std::uint32_t>(sequence % 3);
  scan.resize(points);
  for (std::uint32_t i = 0; i < points; ++i) {
    const Values v = valuesAt(sequence, i);
    scan.x[i] = v.x;
    scan.y[i] = v.y;
    scan.z[i] = v.z;
    scan.intensity[i] = v.intensity;
    scan.ring[i] = v.ring;
    scan.offset_ns[i] = v.offset_ns;
    scan.return_index[i] = v.return_index;
  }
}

std::string checkPattern(const Scan& scan, std::uint32_t max_points) {
  const std::uint64_t seq = scan.sequence;
  const std::string where = "scan " + std::to_string(seq) + ": ";
  const std::uint32_t n = patternPoints(seq, max_points);
  if (scan.size() != n) return where + std::to_string(scan.size()) + " points, expected " + std::to_string(n);
  if (scan.y.size() != n || scan.z.size() != n || scan.intensity.size() != n || scan.ring.size() != n ||
      scan.offset_ns.size() != n || scan.return_index.size() != n) {
    return where + "arrays of different lengths";
  }
  if (scan.stamp_ns != 1'600'000'000'000'000'000 + static_cast<std::int64_t>(seq) * 100'000'000) {
    return where + "wrong stamp_ns";
  }
  if (scan.missing_packets != seq % 3) return where + "wrong missing_packets";
  for (std::uint32_t i = 0; i < n; ++i) {
    const Values v = valuesAt(seq, i);
    if (!same(scan.x[i], v.x) || !same(scan.y[i], v.y) || !same(scan.z[i], v.z) ||
        !same(scan.intensity[i], v.intensity) || scan.ring[i] != v.ring ||
        scan.offset_ns[i] != v.offset_ns || scan.return_index[i] != v.return_index) {
      return where + "point " + std::to_string(i) + " differs";
    }
  }
  return {};
}

}  // namespace rigcal::shm::test
