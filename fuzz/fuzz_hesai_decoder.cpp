// libFuzzer harness: feeds a sequence of packets to a Hesai decoder (fresh per input).
// Input: byte 0 selects the model (mod the number of models), byte 1 options (bit 0: host-receive time, bit 1: repair
// each packet's header and size so that the body and tail get explored), then packets as
// [length u16 little endian][bytes]. After the packets the decoder is flushed.
#include <cstddef>
#include <cstdint>
#include <cstring>
#include <vector>

#include "rigcal/drivers/hesai/hesai_decoder.hpp"

using namespace rigcal;
using namespace rigcal::drivers;

namespace {

hesai::Calibration calibrationFor(const hesai::ModelSpec& spec) {
  hesai::Calibration cal;
  for (int c = 0; c < spec.channels; ++c) {
    cal.elevation_deg.push_back(52.0 - 104.0 * c / spec.channels);
    cal.azimuth_offset_deg.push_back(spec.model == hesai::Model::kQT128 ? ((c * 37) % 41 - 20) * 0.5 : 0.1 * (c % 3));
  }
  return cal;
}

std::size_t expectedSize(const hesai::ModelSpec& spec) {
  switch (spec.protocol) {
    case hesai::Protocol::kQt32: return 1127;
    case hesai::Protocol::kPandar40P: return spec.blocks * (4 + 3 * spec.channels) + 22;
    case hesai::Protocol::kPandar64: return 8 + spec.blocks * (2 + 3 * spec.channels) + 26;
    case hesai::Protocol::kQt31:
    case hesai::Protocol::kXt61: break;
  }
  return 12 + spec.blocks * (2 + 4 * spec.channels) + 28;
}

void repair(const hesai::ModelSpec& spec, std::vector<std::uint8_t>& p) {
  p.resize(expectedSize(spec), 0);
  if (spec.protocol == hesai::Protocol::kPandar40P) {
    for (std::size_t b = 0; b < spec.blocks; ++b) {
      const std::size_t at = b * (4 + 3 * std::size_t(spec.channels));
      p[at] = 0xFF, p[at + 1] = 0xEE;
    }
    return;
  }
  p[0] = 0xEE, p[1] = 0xFF;
  if (spec.protocol == hesai::Protocol::kPandar64) {
    p[2] = static_cast<std::uint8_t>(spec.channels), p[3] = static_cast<std::uint8_t>(spec.blocks);
    return;
  }
  p[2] = spec.protocol_major, p[3] = spec.protocol_minor;
  p[6] = static_cast<std::uint8_t>(spec.channels), p[7] = static_cast<std::uint8_t>(spec.blocks);
  p[11] = spec.model == hesai::Model::kQT128 ? 0x1D : 0x01;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 2) return 0;
  const auto models = hesai::allModels();
  const hesai::ModelSpec& spec = models[data[0] % models.size()];
  const std::uint8_t options = data[1];
  DecoderConfig config;
  config.model = std::string(spec.name);
  config.time_source = (options & 1) ? TimeSource::kHostReceive : TimeSource::kSensorClock;
  HesaiDecoder decoder(spec, calibrationFor(spec), config);
  DecodedPacket out;
  std::vector<std::uint8_t> payload;
  std::size_t at = 2;
  TimeNs receive = 1'700'000'000LL * kNsPerSec;
  while (at + 2 <= size) {
    const std::size_t length = data[at] | (std::size_t(data[at + 1]) << 8);
    at += 2;
    const std::size_t n = std::min(length, size - at);
    payload.assign(data + at, data + at + n);
    at += n;
    if (options & 2) repair(spec, payload);
    UdpPacket packet;
    packet.payload = payload;
    packet.receive_ns = receive;
    receive += 100'000;
    decoder.decode(packet, out);
    if (out.kind == DecodedPacket::Kind::kData && out.points.size() != out.azimuth_deg.size()) __builtin_trap();
    if (out.kind == DecodedPacket::Kind::kMalformed && out.error.empty()) __builtin_trap();
    for (float az : out.azimuth_deg)
      if (!(az >= 0.f && az < 360.f)) __builtin_trap();
  }
  decoder.flush(out);
  return 0;
}
