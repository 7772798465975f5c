#pragma once
// Helpers for the RoboSense tests: a capture held in memory, sweeps cut from it, a point-set match.
#include <cmath>
#include <cstdint>
#include <filesystem>
#include <unordered_map>
#include <vector>

#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/drivers/scan_assembler.hpp"

namespace rigcal::drivers::robosense_test {

struct Capture {
  std::vector<std::vector<std::uint8_t>> payloads;
  std::vector<TimeNs> receive_ns;
  std::vector<std::uint16_t> port;
  [[nodiscard]] std::size_t size() const { return payloads.size(); }
  [[nodiscard]] UdpPacket packet(std::size_t i) const {
    UdpPacket p;
    p.payload = payloads[i];
    p.receive_ns = receive_ns[i];
    p.destination.port = port[i];
    return p;
  }
};

inline Capture loadCapture(const std::filesystem::path& file) {
  Capture c;
  PcapSource source(file);
  while (auto p = source.next()) {
    c.payloads.emplace_back(p->payload.begin(), p->payload.end());
    c.receive_ns.push_back(p->receive_ns);
    c.port.push_back(p->destination.port);
  }
  return c;
}

inline std::vector<Scan> decodeScans(PacketDecoder& decoder, const Capture& capture, AssemblerStats* stats = nullptr) {
  std::vector<Scan> scans;
  ScanAssembler assembler("robosense", AssemblerConfig{}, [&](Scan&& s) { scans.push_back(std::move(s)); });
  DecodedPacket out;
  for (std::size_t i = 0; i < capture.size(); ++i) {
    decoder.decode(capture.packet(i), out);
    assembler.add(out);
  }
  decoder.flush(out);
  assembler.add(out);
  assembler.flush();
  if (stats) *stats = assembler.stats();
  return scans;
}

struct Xyz {
  double x, y, z;
};

/// How many of `query` have a point of `cloud` within `tolerance` metres (grid of cells of that size).
inline std::size_t countMatched(const std::vector<Xyz>& cloud, const std::vector<Xyz>& query, double tolerance) {
  auto cell = [&](double v) { return static_cast<std::int64_t>(std::floor(v / tolerance)); };
  auto key = [](std::int64_t i, std::int64_t j, std::int64_t k) {
    return static_cast<std::uint64_t>((i * 73856093) ^ (j * 19349663) ^ (k * 83492791));
  };
  std::unordered_multimap<std::uint64_t, std::size_t> grid;
  grid.reserve(cloud.size() * 2);
  for (std::size_t n = 0; n < cloud.size(); ++n)
    grid.emplace(key(cell(cloud[n].x), cell(cloud[n].y), cell(cloud[n].z)), n);
  std::size_t matched = 0;
  for (const Xyz& q : query) {
    bool found = false;
    const std::int64_t ci = cell(q.x), cj = cell(q.y), ck = cell(q.z);
    for (std::int64_t di = -1; di <= 1 && !found; ++di)
      for (std::int64_t dj = -1; dj <= 1 && !found; ++dj)
        for (std::int64_t dk = -1; dk <= 1 && !found; ++dk) {
          auto [a, b] = grid.equal_range(key(ci + di, cj + dj, ck + dk));
          for (auto it = a; it != b && !found; ++it) {
            const Xyz& p = cloud[it->second];
            const double dx = p.x - q.x, dy = p.y - q.y, dz = p.z - q.z;
            found = dx * dx + dy * dy + dz * dz <= tolerance * tolerance;
          }
        }
    matched += found;
  }
  return matched;
}

inline std::vector<Xyz> xyzOf(const Scan& scan) {
  std::vector<Xyz> v(scan.size());
  for (std::size_t i = 0; i < scan.size(); ++i) v[i] = {scan.x[i], scan.y[i], scan.z[i]};
  return v;
}

}  // namespace rigcal::drivers::robosense_test
