// libFuzzer harness: feeds a sequence of packets to an RS-Helios-16P decoder (fresh per input).
// Input: byte 0 options (bit 0: host-receive time; bit 1: repair each packet's MSOP id, block ids and
// size so that blocks and channels get explored; bit 2: send a valid DIFOP first, so MSOP packets decode
// at once instead of waiting; bit 3: that DIFOP says dual return), then packets as
// [length u16 little endian][bytes]. After the packets the decoder is flushed.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "rigcal/drivers/robosense/robosense_decoder.hpp"

using namespace rigcal;
using namespace rigcal::drivers;

namespace {

std::vector<std::uint8_t> validDifop(bool dual) {
  std::vector<std::uint8_t> p(robosense::kPacketSize, 0);
  const std::uint8_t id[8] = {0xA5, 0xFF, 0x00, 0x5A, 0x11, 0x11, 0x55, 0x55};
  for (int i = 0; i < 8; ++i) p[std::size_t(i)] = id[i];
  p[8] = 600 >> 8, p[9] = 600 & 0xFF;           // rpm
  p[34] = 36000 >> 8, p[35] = 36000 & 0xFF;     // FOV end
  p[300] = dual ? 0x00 : 0x04;
  for (int l = 0; l < robosense::kLasers; ++l) {
    const int v = 1500 - 200 * l, h = (l % 2 ? 1 : -1) * 400;
    std::uint8_t* a = p.data() + 468 + 3 * l;
    a[0] = v < 0, a[1] = std::uint8_t((v < 0 ? -v : v) >> 8), a[2] = std::uint8_t(v < 0 ? -v : v);
    std::uint8_t* b = p.data() + 564 + 3 * l;
    b[0] = h < 0, b[1] = std::uint8_t((h < 0 ? -h : h) >> 8), b[2] = std::uint8_t(h < 0 ? -h : h);
  }
  return p;
}

void repair(std::vector<std::uint8_t>& p) {
  p.resize(robosense::kPacketSize, 0);
  p[0] = 0x55, p[1] = 0xAA, p[2] = 0x05, p[3] = 0x5A;
  for (int b = 0; b < robosense::kBlocks; ++b) {
    std::uint8_t* blk = p.data() + robosense::kHeaderSize + std::size_t(b) * robosense::kBlockSize;
    blk[0] = 0xFF, blk[1] = 0xEE;
    blk[2] %= 0x8C;  // azimuth below 36000
  }
  p[robosense::kTimestampOffset + 6] = 0;  // µs below 1e6
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::uint8_t options = data[0];
  DecoderConfig config;
  config.model = "RS-Helios-16P";
  config.time_source = (options & 1) ? TimeSource::kHostReceive : TimeSource::kSensorClock;
  RobosenseDecoder decoder(config);
  DecodedPacket out;
  TimeNs receive = 1'700'000'000LL * kNsPerSec;
  auto check = [&] {
    if (out.points.size() != out.azimuth_deg.size()) __builtin_trap();
    if (out.kind == DecodedPacket::Kind::kMalformed && out.error.empty()) __builtin_trap();
    for (float az : out.azimuth_deg)
      if (!(az >= 0.f && az < 360.f)) __builtin_trap();
  };
  std::vector<std::uint8_t> payload;
  if (options & 4) {
    payload = validDifop(options & 8);
    UdpPacket packet;
    packet.payload = payload;
    decoder.decode(packet, out);
    if (out.kind == DecodedPacket::Kind::kMalformed) __builtin_trap();
  }
  std::size_t at = 1;
  while (at + 2 <= size) {
    const std::size_t length = data[at] | (std::size_t(data[at + 1]) << 8);
    at += 2;
    const std::size_t n = std::min(length, size - at);
    payload.assign(data + at, data + at + n);
    at += n;
    if ((options & 2) && !robosense::isDifop(payload)) repair(payload);
    UdpPacket packet;
    packet.payload = payload;
    packet.receive_ns = receive;
    receive += 700'000;
    decoder.decode(packet, out);
    check();
  }
  decoder.flush(out);
  check();
  return 0;
}
