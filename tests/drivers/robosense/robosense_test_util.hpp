#pragma once
// Helpers for the RoboSense tests: a capture held in memory, sweeps cut from it, a point-set match.
#include <cstdint>
#include <filesystem>
#include <vector>

#include "point_set_match.hpp"
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

using rigcal::test::countMatched;
using rigcal::test::xyzOf;
using rigcal::test::Xyz;

}  // namespace rigcal::drivers::robosense_test
