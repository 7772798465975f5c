// Decode throughput of the Hesai decoder on the real captures (payloads held in memory).
// Each iteration decodes one packet, cycling through the capture; reports the time per packet and
// points/s. Needs ../shared/data (or $RIGCAL_DATA_DIR).
#include "bench_support.hpp"
#include "rigcal/drivers/hesai/hesai_decoder.hpp"

namespace {

using namespace rigcal;
using namespace rigcal::drivers;

void decodeBench(benchmark::State& state, const char* model, const char* capture, const char* calibration) {
  const auto dir = bench::dataDir() / "hesai";
  if (bench::skipUnlessPresent(state, {dir / capture, dir / calibration})) return;
  DecoderConfig config;
  config.model = model;
  config.calibration = dir / calibration;
  config.min_range_m = 0.05f;
  HesaiDecoder decoder(config);
  bench::decodeLoop(state, decoder, bench::loadPayloads(dir / capture));
}

}  // namespace

#define HESAI_BENCH(name, model, pcap, csv) \
  BENCHMARK_CAPTURE(decodeBench, name, model, pcap, csv)->ComputeStatistics("p99", rigcal::bench::p99)
HESAI_BENCH(PandarXT32_dual, "PandarXT32", "xt32_dual.pcap", "PandarXT32.csv");
HESAI_BENCH(PandarXT16_dual, "PandarXT16", "xt16_dual.pcap", "PandarXT16.csv");
HESAI_BENCH(PandarQT128_dual, "PandarQT128", "qt128_laststrongest.pcap", "PandarQT128.csv");
HESAI_BENCH(Pandar40P_dual, "Pandar40P", "pandar40p_dual.pcap", "Pandar40P.csv");
HESAI_BENCH(Pandar64_dual, "Pandar64", "pandar64_dual.pcap", "Pandar64.csv");
HESAI_BENCH(PandarQT64_dual, "PandarQT64", "pandarqt64_dual.pcap", "PandarQT64.csv");
HESAI_BENCH(PandarXT32M_laststrongest, "PandarXT32M", "xt32m_laststrongest.pcap", "PandarXT32M.csv");
