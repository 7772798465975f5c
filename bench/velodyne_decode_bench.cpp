// Velodyne decode throughput on the real captures: every data payload is loaded into memory once,
// then decoded packet after packet (the stream wraps around at the end of the capture).
// Needs ../shared/data (or $RIGCAL_DATA_DIR); each benchmark reports an error when it is absent.
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <string>
#include <vector>

#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/drivers/velodyne/velodyne_decoder.hpp"

namespace {

using namespace rigcal;
using namespace rigcal::drivers;

std::filesystem::path dataDir() {
  if (const char* env = std::getenv("RIGCAL_DATA_DIR"); env && *env) return env;
  return RIGCAL_DEFAULT_DATA_DIR;
}

struct Capture {
  std::vector<std::vector<std::uint8_t>> payloads;
  std::vector<TimeNs> receive_ns;
};

Capture load(const std::filesystem::path& pcap) {
  Capture c;
  PcapSource source(pcap);
  while (auto p = source.next()) {
    if (p->payload.size() != 1206) continue;  // data packets only
    c.payloads.emplace_back(p->payload.begin(), p->payload.end());
    c.receive_ns.push_back(p->receive_ns);
  }
  return c;
}

void decodeCapture(benchmark::State& state, const std::string& pcap, const std::string& model,
                   const std::string& calibration, bool nebula_azimuth) {
  const auto dir = dataDir() / "velodyne";
  if (!std::filesystem::exists(dir / pcap)) {
    state.SkipWithError(("shared test data not found: " + (dir / pcap).string() + " (set RIGCAL_DATA_DIR)").c_str());
    return;
  }
  const Capture capture = load(dir / pcap);
  DecoderConfig config;
  config.model = model;
  if (!calibration.empty()) config.calibration = dir / calibration;
  VelodyneOptions options;
  options.nebula_azimuth = nebula_azimuth;
  auto decoder = makeVelodyneDecoder(config, options);
  DecodedPacket out;
  std::size_t i = 0, points = 0, packets = 0;
  UdpPacket packet;
  for (auto _ : state) {
    packet.payload = capture.payloads[i];
    packet.receive_ns = capture.receive_ns[i];
    decoder->decode(packet, out);
    benchmark::DoNotOptimize(out.points.data());
    points += out.points.size();
    ++packets;
    if (++i == capture.payloads.size()) i = 0;
  }
  state.counters["points/s"] = benchmark::Counter(double(points), benchmark::Counter::kIsRate);
  state.counters["time/packet"] =
      benchmark::Counter(double(packets), benchmark::Counter::kIsRate | benchmark::Counter::kInvert);
  state.counters["points/packet"] = benchmark::Counter(double(points) / double(std::max<std::size_t>(packets, 1)));
}

double maxOf(const std::vector<double>& v) { return v.empty() ? 0.0 : *std::max_element(v.begin(), v.end()); }

#define VELODYNE_BENCH(name, pcap, model, calibration, nebula)                                      \
  void name(benchmark::State& state) { decodeCapture(state, pcap, model, calibration, nebula); } \
  BENCHMARK(name)->ComputeStatistics("max", maxOf)

VELODYNE_BENCH(BM_Vlp16Dual, "vlp16_dual.pcap", "VLP-16", "VLP16.calibration.yaml", false);
VELODYNE_BENCH(BM_Vlp16Single, "vlp16_20hz_veloview.pcap", "VLP-16", "VLP-16.xml", false);
VELODYNE_BENCH(BM_Vlp32c, "vlp32c_fov270to90.pcap", "VLP-32C", "VLP32.calibration.yaml", false);
VELODYNE_BENCH(BM_Hdl32e, "hdl32e_example.pcap", "HDL-32E", "", false);
VELODYNE_BENCH(BM_Vls128, "vls128_strongest.pcap", "VLS-128", "VLS128.calibration.yaml", false);
VELODYNE_BENCH(BM_Vls128NebulaAzimuth, "vls128_strongest.pcap", "VLS-128", "VLS128.calibration.yaml", true);

}  // namespace
