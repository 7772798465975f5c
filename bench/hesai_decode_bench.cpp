// Decode throughput of the Hesai decoder on the real captures (payloads held in memory).
// Each iteration decodes one packet, cycling through the capture; reports ns/packet (the time per
// iteration) and points/s. Needs ../shared/data (or $RIGCAL_DATA_DIR).
#include <benchmark/benchmark.h>

#include <algorithm>
#include <cstdlib>
#include <filesystem>
#include <vector>

#include "rigcal/drivers/hesai/hesai_decoder.hpp"
#include "rigcal/drivers/pcap_source.hpp"

namespace {

using namespace rigcal;
using namespace rigcal::drivers;

std::filesystem::path dataDir() {
  if (const char* env = std::getenv("RIGCAL_DATA_DIR"); env && *env) return env;
  return RIGCAL_DEFAULT_DATA_DIR;
}

struct Payloads {
  std::vector<std::vector<std::uint8_t>> packets;
  std::vector<TimeNs> receive_ns;
};

Payloads load(const std::filesystem::path& file) {
  Payloads p;
  PcapSource source(file);
  while (auto packet = source.next()) {
    p.packets.emplace_back(packet->payload.begin(), packet->payload.end());
    p.receive_ns.push_back(packet->receive_ns);
  }
  return p;
}

void decodeBench(benchmark::State& state, const char* model, const char* capture, const char* calibration) {
  const auto dir = dataDir() / "hesai";
  if (!std::filesystem::exists(dir / capture) || !std::filesystem::exists(dir / calibration)) {
    state.SkipWithError(("shared test data not found under " + dir.string() + " (set RIGCAL_DATA_DIR)").c_str());
    return;
  }
  const Payloads payloads = load(dir / capture);
  DecoderConfig config;
  config.model = model;
  config.calibration = dir / calibration;
  config.min_range_m = 0.05f;
  HesaiDecoder decoder(config);
  DecodedPacket out;
  out.points.reserve(4096);
  out.azimuth_deg.reserve(4096);
  std::size_t i = 0, points = 0;
  for (auto _ : state) {
    UdpPacket packet;
    packet.payload = payloads.packets[i];
    packet.receive_ns = payloads.receive_ns[i];
    decoder.decode(packet, out);
    points += out.points.size();
    benchmark::DoNotOptimize(out.points.data());
    if (++i == payloads.packets.size()) i = 0;
  }
  state.counters["points/s"] = benchmark::Counter(static_cast<double>(points), benchmark::Counter::kIsRate);
  state.counters["points/packet"] =
      benchmark::Counter(static_cast<double>(points), benchmark::Counter::kAvgIterations);
}

double p99(const std::vector<double>& v) {
  std::vector<double> s = v;
  std::sort(s.begin(), s.end());
  if (s.empty()) return 0;
  const std::size_t k = static_cast<std::size_t>(0.99 * static_cast<double>(s.size() - 1) + 0.5);
  return s[std::min(k, s.size() - 1)];
}

}  // namespace

BENCHMARK_CAPTURE(decodeBench, PandarXT32_dual, "PandarXT32", "xt32_dual.pcap", "PandarXT32.csv")
    ->ComputeStatistics("p99", p99);
BENCHMARK_CAPTURE(decodeBench, PandarXT16_dual, "PandarXT16", "xt16_dual.pcap", "PandarXT16.csv")
    ->ComputeStatistics("p99", p99);
BENCHMARK_CAPTURE(decodeBench, PandarQT128_dual, "PandarQT128", "qt128_laststrongest.pcap", "PandarQT128.csv")
    ->ComputeStatistics("p99", p99);
