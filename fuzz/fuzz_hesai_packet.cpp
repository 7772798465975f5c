// libFuzzer harness: one UDP payload parsed as a packet of every Hesai model (each packet format's
// parser, hesai_packet.cpp), and restamped as `rigcal replay --clock now` does. Seeds are raw payloads
// of the real captures. Checks: a parsed packet's blocks and tail lie inside the payload, the return
// count divides the blocks, and a restamped packet still parses with the same layout.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "rigcal/drivers/hesai/hesai_packet.hpp"
#include "rigcal/drivers/packet_restamper.hpp"

using namespace rigcal::drivers;

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> payload(data, size);
  std::vector<std::uint8_t> copy;
  for (const hesai::ModelSpec& spec : hesai::allModels()) {
    hesai::PacketView v;
    if (!hesai::parsePacket(spec, payload, v).empty()) continue;
    if (v.returns < 1 || v.blocks % v.returns != 0) __builtin_trap();
    const std::uint8_t* end = data + size;
    if (v.block(v.blocks - 1) + v.blockBytes() > end || v.tail < v.block(v.blocks - 1) || v.tail >= end)
      __builtin_trap();
    if (hesai::tailTimestampOffset(spec) + 4 > std::size_t(end - v.tail)) __builtin_trap();
    DecoderConfig config;
    config.model = std::string(spec.name);
    const PacketRestamper restamper(config);
    copy.assign(data, data + size);
    const std::int64_t shift_us = (std::int64_t(size) * 7919 % 2'000'000'000) - 1'000'000'000;
    if (restamper.restamp(copy, shift_us)) {
      hesai::PacketView after;
      if (!hesai::parsePacket(spec, copy, after).empty() || after.returns != v.returns) __builtin_trap();
    }
  }
  return 0;
}
