#pragma once
// What the benchmarks share: where the real captures are, the p99 statistic over repetitions, and the
// decode loop of the vendor decoder benchmarks (payloads held in memory, decoded one after the other).
#include <benchmark/benchmark.h>

#include <cstdint>
#include <filesystem>
#include <functional>
#include <vector>

#include "rigcal/drivers/packet_decoder.hpp"

namespace rigcal::bench {

/// $RIGCAL_DATA_DIR, else ../shared/data beside the source tree.
std::filesystem::path dataDir();

/// Nearest-rank 99th percentile (with 10 repetitions: the slowest one); 0 for no samples.
double p99(const std::vector<double>& samples);

/// Every UDP payload of a capture (and its receive time) that `keep` accepts, in capture order.
struct CapturedPayloads {
  std::vector<std::vector<std::uint8_t>> payloads;
  std::vector<TimeNs> receive_ns;
  [[nodiscard]] std::size_t size() const { return payloads.size(); }
};
CapturedPayloads loadPayloads(const std::filesystem::path& pcap,
                              const std::function<bool(std::size_t payload_bytes)>& keep = {});

/// True (after SkipWithError naming them) when any of `files` is missing: the benchmark returns.
bool skipUnlessPresent(benchmark::State& state, const std::vector<std::filesystem::path>& files);

/// Decodes `capture` packet after packet (wrapping around) while the benchmark runs; reports points/s,
/// points/packet and the time per packet.
void decodeLoop(benchmark::State& state, drivers::PacketDecoder& decoder, const CapturedPayloads& capture);

}  // namespace rigcal::bench
