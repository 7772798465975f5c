#pragma once
// Builds synthetic Velodyne data packets for the decoder tests.
#include <array>
#include <cstdint>
#include <vector>

#include "rigcal/drivers/udp_packet.hpp"
#include "rigcal/drivers/velodyne/velodyne_packet.hpp"

namespace rigcal::test {

struct VelodynePacketBuilder {
  std::vector<std::uint8_t> bytes = std::vector<std::uint8_t>(drivers::velodyne::kDataPacketSize, 0);

  VelodynePacketBuilder(std::uint8_t product, std::uint8_t mode, std::uint32_t micros) {
    bytes[1204] = mode;
    bytes[1205] = product;
    setTimestamp(micros);
    for (int b = 0; b < 12; ++b) setHeader(b, 0xEEFF);
  }
  VelodynePacketBuilder& setTimestamp(std::uint32_t micros) {
    for (int i = 0; i < 4; ++i) bytes[1200 + i] = static_cast<std::uint8_t>(micros >> (8 * i));
    return *this;
  }
  VelodynePacketBuilder& setHeader(int block, std::uint16_t header) {
    put16(block * 100, header);
    return *this;
  }
  VelodynePacketBuilder& setAzimuth(int block, std::uint16_t hundredths) {
    put16(block * 100 + 2, hundredths);
    return *this;
  }
  /// Azimuths start, start+step, ... (mod 36000) for blocks 0..11; `per` blocks share an azimuth
  /// (2 for dual return, 4 for the VLS-128 banks).
  VelodynePacketBuilder& rampAzimuth(int start, int step, int per = 1) {
    for (int b = 0; b < 12; ++b) setAzimuth(b, static_cast<std::uint16_t>((start + step * (b / per)) % 36000));
    return *this;
  }
  VelodynePacketBuilder& setReturn(int block, int channel, std::uint16_t distance, std::uint8_t intensity) {
    put16(block * 100 + 4 + 3 * channel, distance);
    bytes[block * 100 + 4 + 3 * channel + 2] = intensity;
    return *this;
  }
  /// Every channel of every block returns `distance`.
  VelodynePacketBuilder& fill(std::uint16_t distance, std::uint8_t intensity = 10) {
    for (int b = 0; b < 12; ++b)
      for (int c = 0; c < 32; ++c) setReturn(b, c, distance, intensity);
    return *this;
  }
  [[nodiscard]] drivers::UdpPacket packet(TimeNs receive_ns = 0) const {
    drivers::UdpPacket p;
    p.payload = bytes;
    p.receive_ns = receive_ns;
    p.destination.port = 2368;
    return p;
  }

 private:
  void put16(int at, std::uint16_t v) {
    bytes[at] = static_cast<std::uint8_t>(v & 0xFF);
    bytes[at + 1] = static_cast<std::uint8_t>(v >> 8);
  }
};

}  // namespace rigcal::test
