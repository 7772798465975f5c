// Decode throughput of the RS-Helios-16P decoder on the real capture (payloads held in memory).
// The DIFOP packet is decoded once first (angles known), then each iteration decodes one MSOP packet,
// cycling through the capture; reports the time per packet and points/s. Needs ../shared/data.
#include <algorithm>

#include "bench_support.hpp"
#include "rigcal/drivers/robosense/robosense_decoder.hpp"

namespace {

using namespace rigcal;
using namespace rigcal::drivers;

void decodeBench(benchmark::State& state, float min_range_m) {
  const auto pcap = bench::dataDir() / "robosense/helios16p.pcap";
  if (bench::skipUnlessPresent(state, {pcap})) return;
  DecoderConfig config;
  config.model = "RS-Helios-16P";
  config.min_range_m = min_range_m;
  RobosenseDecoder decoder(config);
  bench::CapturedPayloads capture = bench::loadPayloads(pcap);
  const auto difop = std::find_if(capture.payloads.begin(), capture.payloads.end(),
                                  [](const auto& p) { return robosense::isDifop(p); });
  if (difop == capture.payloads.end()) {
    state.SkipWithError("helios16p.pcap holds no DIFOP packet");
    return;
  }
  UdpPacket packet;
  packet.payload = *difop;
  DecodedPacket out;
  decoder.decode(packet, out);
  capture.receive_ns.erase(capture.receive_ns.begin() + (difop - capture.payloads.begin()));
  capture.payloads.erase(difop);
  bench::decodeLoop(state, decoder, capture);
}

}  // namespace

// 0.2 m: the reference's range filter (~100 points per packet); 0.1 m: the sensor's, with the
// near-field returns this capture is full of (~190 points per packet).
BENCHMARK_CAPTURE(decodeBench, RS_Helios_16P_single_0_2m, 0.2f)->ComputeStatistics("p99", rigcal::bench::p99);
BENCHMARK_CAPTURE(decodeBench, RS_Helios_16P_single_0_1m, 0.1f)->ComputeStatistics("p99", rigcal::bench::p99);
