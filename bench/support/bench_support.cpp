#include "bench_support.hpp"

#include <algorithm>
#include <cmath>
#include <cstdlib>
#include <string>

#include "rigcal/drivers/pcap_source.hpp"

namespace rigcal::bench {

std::filesystem::path dataDir() {
  if (const char* env = std::getenv("RIGCAL_DATA_DIR"); env && *env) return env;
  return RIGCAL_DEFAULT_DATA_DIR;
}

double p99(const std::vector<double>& samples) {
  if (samples.empty()) return 0;
  std::vector<double> s(samples);
  std::sort(s.begin(), s.end());
  const auto rank = static_cast<std::size_t>(std::ceil(0.99 * static_cast<double>(s.size())));
  return s[std::max<std::size_t>(rank, 1) - 1];
}

CapturedPayloads loadPayloads(const std::filesystem::path& pcap,
                              const std::function<bool(std::size_t payload_bytes)>& keep) {
  CapturedPayloads c;
  drivers::PcapSource source(pcap);
  while (auto p = source.next()) {
    if (keep && !keep(p->payload.size())) continue;
    c.payloads.emplace_back(p->payload.begin(), p->payload.end());
    c.receive_ns.push_back(p->receive_ns);
  }
  return c;
}

bool skipUnlessPresent(benchmark::State& state, const std::vector<std::filesystem::path>& files) {
  for (const auto& f : files) {
    if (std::filesystem::exists(f)) continue;
    state.SkipWithError(("shared data not found: " + f.string() + " (set RIGCAL_DATA_DIR)").c_str());
    return true;
  }
  return false;
}

void decodeLoop(benchmark::State& state, drivers::PacketDecoder& decoder, const CapturedPayloads& capture) {
  if (capture.payloads.empty()) {
    state.SkipWithError("no data packets in the capture");
    return;
  }
  drivers::DecodedPacket out;
  drivers::UdpPacket packet;
  std::size_t i = 0, points = 0, packets = 0;
  for (auto _ : state) {
    packet.payload = capture.payloads[i];
    packet.receive_ns = capture.receive_ns[i];
    decoder.decode(packet, out);
    benchmark::DoNotOptimize(out.points.data());
    points += out.points.size();
    ++packets;
    if (++i == capture.payloads.size()) i = 0;
  }
  using benchmark::Counter;
  state.counters["points/s"] = Counter(static_cast<double>(points), Counter::kIsRate);
  state.counters["time/packet"] = Counter(static_cast<double>(packets), Counter::kIsRate | Counter::kInvert);
  state.counters["points/packet"] =
      Counter(static_cast<double>(points) / static_cast<double>(std::max<std::size_t>(packets, 1)));
}

}  // namespace rigcal::bench
