#pragma once
// A capture held in memory (payloads, receive times and destination ports of every UDP packet of a pcap)
// and its sweeps decoded by a vendor decoder: what the driver reference and decoder tests share.
#include <cstdint>
#include <filesystem>
#include <string>
#include <vector>

#include "rigcal/drivers/packet_decoder.hpp"
#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/drivers/scan_assembler.hpp"

namespace rigcal::test {

struct CapturedPackets {
  std::vector<std::vector<std::uint8_t>> payloads;
  std::vector<TimeNs> receive_ns;
  std::vector<std::uint16_t> port;
  [[nodiscard]] std::size_t size() const { return payloads.size(); }
  [[nodiscard]] drivers::UdpPacket packet(std::size_t i) const {
    drivers::UdpPacket p;
    p.payload = payloads[i];
    p.receive_ns = receive_ns[i];
    p.destination.port = port[i];
    return p;
  }
};

inline CapturedPackets loadCapture(const std::filesystem::path& file) {
  CapturedPackets c;
  drivers::PcapSource source(file);
  while (auto p = source.next()) {
    c.payloads.emplace_back(p->payload.begin(), p->payload.end());
    c.receive_ns.push_back(p->receive_ns);
    c.port.push_back(p->destination.port);
  }
  return c;
}

/// Decodes every packet of `capture` for which keep(i) is true, flushes the decoder at the end, and cuts
/// sweeps at `cut_deg`.
template <class Keep>
std::vector<Scan> decodeScans(drivers::PacketDecoder& decoder, const CapturedPackets& capture, Keep keep,
                              double cut_deg = 0.0, drivers::AssemblerStats* stats = nullptr) {
  std::vector<Scan> scans;
  drivers::AssemblerConfig config;
  config.cut_angle_deg = cut_deg;
  drivers::ScanAssembler assembler("capture", config, [&](Scan&& s) { scans.push_back(std::move(s)); });
  drivers::DecodedPacket out;
  for (std::size_t i = 0; i < capture.size(); ++i) {
    if (!keep(i)) continue;
    decoder.decode(capture.packet(i), out);
    assembler.add(out);
  }
  decoder.flush(out);
  assembler.add(out);
  assembler.flush();
  if (stats) *stats = assembler.stats();
  return scans;
}

inline std::vector<Scan> decodeScans(drivers::PacketDecoder& decoder, const CapturedPackets& capture,
                                     double cut_deg = 0.0) {
  return decodeScans(decoder, capture, [](std::size_t) { return true; }, cut_deg);
}

inline std::vector<Scan> decodeScans(drivers::PacketDecoder& decoder, const CapturedPackets& capture,
                                     drivers::AssemblerStats* stats) {
  return decodeScans(decoder, capture, [](std::size_t) { return true; }, 0.0, stats);
}

}  // namespace rigcal::test
