#pragma once
// The identity an Ouster sensor stamps into every eUDP packet header (initialization_id, serial
// number) and reports in its sensor_info: both derive from the sensor's name and lidar port, which
// the encoder and the metadata writer both know, so the JSON rig.yaml names and the packets agree
// (rigcal's decoder checks them).
#include <cstdint>
#include <string_view>

#include "rigcal/sim/random.hpp"

namespace rigcal::sim::encoders {

struct OusterIdentity {
  std::uint32_t init_id;  // 24 bits, never 0 (0 means unknown to the decoder)
  std::uint64_t serial;   // 12 decimal digits, like real units (fits the 40-bit header field)
};

inline OusterIdentity ousterIdentity(std::string_view sensor_name, std::uint16_t lidar_port) {
  std::uint64_t h = 0x6f75737465725f69ULL;  // "ouster_i"
  for (char c : sensor_name) h = mix64(h ^ std::uint8_t(c));
  h = mix64(h ^ lidar_port);
  return {std::uint32_t(h & 0xffffffu) | 1u, 992200000000ULL + (h >> 24) % 100000000ULL};
}

}  // namespace rigcal::sim::encoders
