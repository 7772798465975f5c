// Ouster decode throughput: real captures' lidar payloads, loaded once, decoded packet after packet.
// Reports points/s and ns/packet per capture (profile). Needs ../shared/data (or $RIGCAL_DATA_DIR).
#include <benchmark/benchmark.h>

#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "rigcal/drivers/ouster/ouster_decoder.hpp"
#include "rigcal/drivers/pcap_source.hpp"

namespace {

using namespace rigcal;
using namespace rigcal::drivers;

std::filesystem::path dataDir() {
  if (const char* env = std::getenv("RIGCAL_DATA_DIR"); env && *env) return env;
  return RIGCAL_DEFAULT_DATA_DIR;
}

void BM_OusterDecode(benchmark::State& state, const std::string& pcap_name, const std::string& json_name) {
  const auto dir = dataDir() / "ouster";
  if (!std::filesystem::exists(dir / pcap_name)) {
    state.SkipWithError(("shared data not found: " + (dir / pcap_name).string() + " (set RIGCAL_DATA_DIR)").c_str());
    return;
  }
  DecoderConfig config;
  config.model = "Ouster";
  config.metadata = dir / json_name;
  auto decoder = makeOusterDecoder(config);
  std::vector<std::vector<std::uint8_t>> payloads;
  {
    PcapSource source(dir / pcap_name);
    while (auto p = source.next())
      if (p->payload.size() > ouster::kImuPacketSize) payloads.emplace_back(p->payload.begin(), p->payload.end());
  }
  if (payloads.empty()) {
    state.SkipWithError("no lidar packets");
    return;
  }
  DecodedPacket out;
  std::size_t i = 0, points = 0, packets = 0;
  for (auto _ : state) {
    UdpPacket packet;
    packet.payload = payloads[i];
    decoder->decode(packet, out);
    benchmark::DoNotOptimize(out.points.data());
    points += out.points.size();
    ++packets;
    if (++i == payloads.size()) i = 0;
  }
  state.counters["points/s"] = benchmark::Counter(double(points), benchmark::Counter::kIsRate);
  state.counters["ns/packet"] = benchmark::Counter(double(packets) * 1e-9, benchmark::Counter::kIsRate |
                                                                               benchmark::Counter::kInvert);
  state.counters["points/packet"] = double(points) / double(std::max<std::size_t>(packets, 1));
}

}  // namespace

BENCHMARK_CAPTURE(BM_OusterDecode, OS2_32_LEGACY, "OS-2-32-U0_v2.0.0_1024x10.pcap", "OS-2-32-U0_v2.0.0_1024x10.json");
BENCHMARK_CAPTURE(BM_OusterDecode, OS1_64_LEGACY, "OS-1-64_1024x10_fw20.pcap", "OS-1-64_sensor_config_reduced.json");
BENCHMARK_CAPTURE(BM_OusterDecode, OS2_128_RNG19, "OS-2-128-U1_v2.3.0_1024x10.pcap", "OS-2-128-U1_v2.3.0_1024x10.json");
BENCHMARK_CAPTURE(BM_OusterDecode, OS0_32_RNG19_DUAL, "OS-0-32-U1_v2.2.0_1024x10.pcap", "OS-0-32-U1_v2.2.0_1024x10.json");
BENCHMARK_CAPTURE(BM_OusterDecode, OS0_128_RNG15, "OS-0-128-U1_v2.3.0_1024x10.pcap", "OS-0-128-U1_v2.3.0_1024x10.json");
BENCHMARK_CAPTURE(BM_OusterDecode, OS0_128_RNG15_CRC, "crc_test.pcap", "crc_test.json");
