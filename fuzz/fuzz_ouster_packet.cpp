// libFuzzer harness: arbitrary payloads through the Ouster decoder (every UDP profile, both time
// sources, with loss-tracking state carried between inputs) and the raw field scan.
// First byte: which decoder; the rest: the UDP payload. Small layouts (2 beams × 2 columns per packet)
// keep valid sizes within the fuzzer's reach.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <string>
#include <vector>

#include "rigcal/drivers/ouster/ouster_decoder.hpp"
#include "rigcal/drivers/ouster/ouster_raw_scan.hpp"

using namespace rigcal;
using namespace rigcal::drivers;

namespace {

struct Target {
  std::unique_ptr<ouster::OusterDecoder> decoder;
  std::unique_ptr<ouster::RawScan> raw;
};

std::vector<Target> makeTargets() {
  const char* profiles[] = {"LEGACY", "RNG19_RFL8_SIG16_NIR16", "RNG19_RFL8_SIG16_NIR16_DUAL", "RNG15_RFL8_NIR8",
                            "FUSA_RNG15_RFL8_NIR8_DUAL", "FIVE_WORD_PIXEL"};
  std::vector<Target> out;
  for (const char* profile : profiles) {
    for (int variant = 0; variant < 2; ++variant) {
      const std::string text = std::string(R"({"beam_altitude_angles": [10, -10], "beam_azimuth_angles": [1, -1],
        "lidar_mode": "512x20", "initialization_id": 5, "build_rev": "v3.1.0",
        "data_format": {"pixels_per_column": 2, "columns_per_packet": 2, "columns_per_frame": 512,
        "pixel_shift_by_row": [1, -1], "column_window": )") +
                               (variant ? "[500, 20]" : "[0, 511]") + R"(, "udp_profile_lidar": ")" + profile + "\"}}";
      const ouster::Metadata md = ouster::parseMetadata(text, "fuzz.json");
      DecoderConfig config;
      config.model = "Ouster";
      config.time_source = variant ? TimeSource::kHostReceive : TimeSource::kSensorClock;
      config.min_range_m = variant ? 0.0f : 0.3f;
      out.push_back({std::make_unique<ouster::OusterDecoder>(config, md), std::make_unique<ouster::RawScan>(md)});
    }
  }
  return out;
}

}  // namespace

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  static std::vector<Target> targets = makeTargets();
  static DecodedPacket out;
  if (size < 1) return 0;
  Target& t = targets[data[0] % targets.size()];
  UdpPacket packet;
  packet.payload = std::span<const std::uint8_t>(data + 1, size - 1);
  packet.receive_ns = 1'000'000'000;
  t.decoder->decode(packet, out);
  if (out.kind == DecodedPacket::Kind::kMalformed && (out.error.empty() || out.error.find('\n') != std::string::npos))
    __builtin_trap();
  if (out.points.size() != out.azimuth_deg.size()) __builtin_trap();
  if (t.raw->add(packet.payload) == ouster::RawScan::AddResult::kOtherFrame) {
    t.raw->reset();
    t.raw->add(packet.payload);
  }
  return 0;
}
