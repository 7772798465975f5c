#pragma once
// Helpers shared by the Hesai tests: captures held in memory, and a 1 mm point-set match.
#include <cstdint>
#include <filesystem>
#include <vector>

#include "point_set_match.hpp"
#include "rigcal/drivers/hesai/hesai_decoder.hpp"
#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/drivers/scan_assembler.hpp"

namespace rigcal::drivers::hesai_test {

struct Capture {
  std::vector<std::vector<std::uint8_t>> payloads;
  std::vector<TimeNs> receive_ns;
  [[nodiscard]] std::size_t size() const { return payloads.size(); }
  [[nodiscard]] UdpPacket packet(std::size_t i) const {
    UdpPacket p;
    p.payload = payloads[i];
    p.receive_ns = receive_ns[i];
    return p;
  }
};

inline Capture loadCapture(const std::filesystem::path& file) {
  Capture c;
  PcapSource source(file);
  while (auto p = source.next()) {
    c.payloads.emplace_back(p->payload.begin(), p->payload.end());
    c.receive_ns.push_back(p->receive_ns);
  }
  return c;
}

/// Decodes every packet of `capture` (those for which keep(i) is true) and cuts sweeps at `cut_deg`.
template <class Keep>
std::vector<Scan> decodeScans(PacketDecoder& decoder, const Capture& capture, Keep keep, double cut_deg = 0.0,
                              AssemblerStats* stats = nullptr) {
  std::vector<Scan> scans;
  AssemblerConfig config;
  config.cut_angle_deg = cut_deg;
  ScanAssembler assembler("hesai", config, [&](Scan&& s) { scans.push_back(std::move(s)); });
  DecodedPacket out;
  for (std::size_t i = 0; i < capture.size(); ++i) {
    if (!keep(i)) continue;
    decoder.decode(capture.packet(i), out);
    assembler.add(out);
  }
  if (auto* hesai = dynamic_cast<HesaiDecoder*>(&decoder)) {
    hesai->flush(out);
    assembler.add(out);
  }
  assembler.flush();
  if (stats) *stats = assembler.stats();
  return scans;
}

inline std::vector<Scan> decodeScans(PacketDecoder& decoder, const Capture& capture, double cut_deg = 0.0) {
  return decodeScans(decoder, capture, [](std::size_t) { return true; }, cut_deg);
}

using rigcal::test::countMatched;
using rigcal::test::xyzOf;
using rigcal::test::Xyz;

}  // namespace rigcal::drivers::hesai_test
