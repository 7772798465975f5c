#pragma once
// What the Hesai tests share: captures held in memory and decoded (tests/support), a 1 mm point-set match.
#include <cstdint>
#include <filesystem>
#include <vector>

#include "captured_packets.hpp"
#include "point_set_match.hpp"
#include "rigcal/drivers/hesai/hesai_decoder.hpp"

namespace rigcal::drivers::hesai_test {

using Capture = rigcal::test::CapturedPackets;
using rigcal::test::countMatched;
using rigcal::test::decodeScans;
using rigcal::test::loadCapture;
using rigcal::test::xyzOf;
using rigcal::test::Xyz;

/// The payload of a capture's first packet; empty when it has none.
inline std::vector<std::uint8_t> firstPayload(const std::filesystem::path& file) {
  PcapSource source(file);
  auto p = source.next();
  if (!p) return {};
  return {p->payload.begin(), p->payload.end()};
}

}  // namespace rigcal::drivers::hesai_test
