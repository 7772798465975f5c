// Ouster decode throughput: real captures' lidar payloads, loaded once, decoded packet after packet.
// Reports points/s and the time per packet per capture (profile). Needs ../shared/data (or $RIGCAL_DATA_DIR).
#include <string>

#include "bench_support.hpp"
#include "rigcal/drivers/ouster/ouster_decoder.hpp"

namespace {

using namespace rigcal;
using namespace rigcal::drivers;

void BM_OusterDecode(benchmark::State& state, const std::string& pcap_name, const std::string& json_name) {
  const auto dir = bench::dataDir() / "ouster";
  if (bench::skipUnlessPresent(state, {dir / pcap_name, dir / json_name})) return;
  DecoderConfig config;
  config.model = "Ouster";
  config.metadata = dir / json_name;
  auto decoder = makeOusterDecoder(config);
  const bench::CapturedPayloads capture =
      bench::loadPayloads(dir / pcap_name, [](std::size_t bytes) { return bytes > ouster::kImuPacketSize; });
  bench::decodeLoop(state, *decoder, capture);
}

}  // namespace

#define OUSTER_BENCH(name, pcap, json) \
  BENCHMARK_CAPTURE(BM_OusterDecode, name, pcap, json)->ComputeStatistics("p99", rigcal::bench::p99)
OUSTER_BENCH(OS2_32_LEGACY, "OS-2-32-U0_v2.0.0_1024x10.pcap", "OS-2-32-U0_v2.0.0_1024x10.json");
OUSTER_BENCH(OS1_64_LEGACY, "OS-1-64_1024x10_fw20.pcap", "OS-1-64_sensor_config_reduced.json");
OUSTER_BENCH(OS2_128_RNG19, "OS-2-128-U1_v2.3.0_1024x10.pcap", "OS-2-128-U1_v2.3.0_1024x10.json");
OUSTER_BENCH(OS0_32_RNG19_DUAL, "OS-0-32-U1_v2.2.0_1024x10.pcap", "OS-0-32-U1_v2.2.0_1024x10.json");
OUSTER_BENCH(OS0_128_RNG15, "OS-0-128-U1_v2.3.0_1024x10.pcap", "OS-0-128-U1_v2.3.0_1024x10.json");
OUSTER_BENCH(OS0_128_RNG15_CRC, "crc_test.pcap", "crc_test.json");
