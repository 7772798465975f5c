// libFuzzer harness: a stream of UDP payloads through one Velodyne decoder.
// Input: byte 0 chooses model (bits 0-1), time source (bit 2), cut mode (bit 3), nebula azimuth
// (bit 4) and whether payloads get valid framing patched in (bit 5: 1206-byte packets with valid block
// headers, azimuths, product id and timestamp, so the fuzzer reaches the stream logic); then records
// of [u16 length][u32 receive-time step in µs][payload].
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <memory>
#include <vector>

#include "rigcal/drivers/velodyne/velodyne_calibration.hpp"
#include "rigcal/drivers/velodyne/velodyne_decoder.hpp"
#include "rigcal/drivers/velodyne/velodyne_packet.hpp"

namespace {

using namespace rigcal;
using namespace rigcal::drivers;

// One calibration per model, built once: the nominal tables, and a synthetic VLS-128 table.
const velodyne::Calibration& calibration(velodyne::Model model) {
  static const std::vector<velodyne::Calibration> tables = [] {
    std::vector<velodyne::Calibration> t;
    for (auto m : {velodyne::Model::kVlp16, velodyne::Model::kVlp32c, velodyne::Model::kHdl32e})
      t.push_back(*velodyne::nominalCalibration(m));
    velodyne::Calibration vls;
    vls.source = "synthetic VLS-128";
    for (int i = 0; i < 128; ++i)
      vls.lasers.push_back({(i % 8 - 4) * 0.01, -0.4 + 0.0045 * i, 0.01, (i % 3) * 0.01, (i % 5 - 2) * 0.01});
    t.push_back(vls);
    return t;
  }();
  return tables[static_cast<int>(model)];
}

void patchFraming(std::vector<std::uint8_t>& p, velodyne::Model model) {
  using namespace velodyne;
  p.resize(kDataPacketSize);
  const bool dual = p[kReturnModeOffset] & 1;
  p[kReturnModeOffset] = dual ? 0x39 : 0x37;
  p[kProductIdOffset] = 0;
  for (int b = 0; b < kBlocksPerPacket; ++b) {
    const std::uint16_t header = model == Model::kVls128 ? kBankHeaders[(dual ? b / 2 : b) % 4] : 0xEEFF;
    p[b * kBlockSize] = header & 0xFF;
    p[b * kBlockSize + 1] = header >> 8;
    const std::uint16_t az = readU16(&p[b * kBlockSize + 2]) % 36001;
    p[b * kBlockSize + 2] = az & 0xFF;
    p[b * kBlockSize + 3] = az >> 8;
  }
  const std::uint32_t t = readU32(&p[kTimestampOffset]) % kMicrosPerHour;
  std::memcpy(&p[kTimestampOffset], &t, 4);
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  if (size < 1) return 0;
  const std::uint8_t flags = data[0];
  static const char* const kModels[] = {"VLP-16", "VLP-32C", "HDL-32E", "VLS-128"};
  DecoderConfig config;
  config.model = kModels[flags & 3];
  config.time_source = flags & 4 ? TimeSource::kHostReceive : TimeSource::kSensorClock;
  VelodyneOptions options;
  options.cut = flags & 8 ? VelodyneOptions::Cut::kPacket : VelodyneOptions::Cut::kBlock;
  options.nebula_azimuth = flags & 16;
  const bool patch = flags & 32;
  const auto model = *velodyne::parseModel(config.model);
  auto decoder = velodyne::makeDecoder(model, calibration(model), config, options);

  DecodedPacket out;
  TimeNs receive = 1'713'492'000 * kNsPerSec;
  std::size_t at = 1;
  std::vector<std::uint8_t> payload;
  while (at + 6 <= size) {
    const std::size_t length = data[at] | (data[at + 1] << 8);
    std::uint32_t step = 0;
    std::memcpy(&step, data + at + 2, 4);
    at += 6;
    const std::size_t n = std::min(length, size - at);
    payload.assign(data + at, data + at + n);
    at += n;
    if (patch) patchFraming(payload, model);
    receive += static_cast<TimeNs>(step) * kNsPerUs - (TimeNs(1) << 31) * kNsPerUs / 1024;
    UdpPacket packet;
    packet.payload = payload;
    packet.receive_ns = receive;
    decoder->decode(packet, out);
    if (out.points.size() != out.azimuth_deg.size()) __builtin_trap();
    if (out.kind == DecodedPacket::Kind::kMalformed && (out.error.empty() || out.error.find('\n') != std::string::npos))
      __builtin_trap();
    if (out.points.size() > velodyne::kPointsPerPacket) __builtin_trap();
  }
  (void)decoder->scanRateHz();
  return 0;
}
