// Fuzzes the frame parsers and the IPv4 reassembler. The input is read twice:
//  1. whole, as a frame of every link type (parseFrame, then parseUdp on what it finds);
//  2. as a stream of records [link selector:1][length:2 big-endian][frame:length] fed in order through
//     parseFrame and an Ipv4Reassembler (small, to exercise eviction), like PcapSource does.
// Every span a parser returns must lie inside the bytes it was given.
#include <algorithm>
#include <cstdint>
#include <cstdlib>
#include <span>

#include "rigcal/drivers/ipv4_reassembler.hpp"
#include "rigcal/drivers/link_layer.hpp"

using namespace rigcal::drivers;

namespace {

constexpr LinkType kLinkTypes[] = {LinkType::kEthernet, LinkType::kRaw, LinkType::kLinuxSll,
                                   LinkType::kLinuxSll2, LinkType::kIpv4};

void requireInside(std::span<const std::uint8_t> inner, std::span<const std::uint8_t> outer) {
  if (inner.empty()) return;
  if (inner.data() < outer.data() || inner.data() + inner.size() > outer.data() + outer.size()) std::abort();
}

std::uint64_t touch(std::span<const std::uint8_t> bytes) {
  std::uint64_t sum = 0;
  for (const std::uint8_t b : bytes) sum += b;
  return sum;
}

void checkUdp(std::span<const std::uint8_t> datagram) {
  if (const auto udp = parseUdp(datagram)) {
    requireInside(udp->payload, datagram);
    if (udp->payload.size() + 8 > datagram.size()) std::abort();
  }
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  const std::span<const std::uint8_t> input(data, size);
  std::uint64_t sum = 0;

  for (const LinkType link : kLinkTypes) {
    Ipv4Header ip;
    if (parseFrame(link, input, ip) == FrameResult::kIpv4) {
      requireInside(ip.payload, input);
      sum += touch(ip.payload);
      checkUdp(ip.payload);
    }
  }

  Ipv4Reassembler reassembler(4);
  std::size_t at = 0;
  while (at + 3 <= size) {
    const LinkType link = kLinkTypes[data[at] % 5];
    const std::size_t length = std::size_t(data[at + 1]) << 8 | data[at + 2];
    at += 3;
    const std::span<const std::uint8_t> frame = input.subspan(at, std::min(length, size - at));
    at += frame.size();
    Ipv4Header ip;
    if (parseFrame(link, frame, ip) != FrameResult::kIpv4) continue;
    requireInside(ip.payload, frame);
    if (ip.more_fragments || ip.fragment_offset != 0) {
      const auto whole = reassembler.add(ip);
      if (whole.size() > 65535) std::abort();
      sum += touch(whole);
      checkUdp(whole);
    } else {
      checkUdp(ip.payload);
    }
  }
  if (sum == 0xdeadbeefdeadbeefULL) std::abort();  // keep the reads
  return 0;
}
