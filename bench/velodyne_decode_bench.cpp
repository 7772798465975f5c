// Velodyne decode throughput on the real captures: every data payload is loaded into memory once,
// then decoded packet after packet (the stream wraps around at the end of the capture).
// Needs ../shared/data (or $RIGCAL_DATA_DIR); each benchmark reports an error when it is absent.
#include <string>

#include "bench_support.hpp"
#include "rigcal/drivers/velodyne/velodyne_decoder.hpp"

namespace {

using namespace rigcal;
using namespace rigcal::drivers;

void decodeCapture(benchmark::State& state, const std::string& pcap, const std::string& model,
                   const std::string& calibration, bool nebula_azimuth) {
  const auto dir = bench::dataDir() / "velodyne";
  if (bench::skipUnlessPresent(state, {dir / pcap})) return;
  const bench::CapturedPayloads capture =
      bench::loadPayloads(dir / pcap, [](std::size_t bytes) { return bytes == 1206; });  // data packets only
  DecoderConfig config;
  config.model = model;
  if (!calibration.empty()) config.calibration = dir / calibration;
  VelodyneOptions options;
  options.nebula_azimuth = nebula_azimuth;
  auto decoder = makeVelodyneDecoder(config, options);
  bench::decodeLoop(state, *decoder, capture);
}

#define VELODYNE_BENCH(name, pcap, model, calibration, nebula)                                      \
  void name(benchmark::State& state) { decodeCapture(state, pcap, model, calibration, nebula); } \
  BENCHMARK(name)->ComputeStatistics("p99", bench::p99)

VELODYNE_BENCH(BM_Vlp16Dual, "vlp16_dual.pcap", "VLP-16", "VLP16.calibration.yaml", false);
VELODYNE_BENCH(BM_Vlp16Single, "vlp16_20hz_veloview.pcap", "VLP-16", "VLP-16.xml", false);
VELODYNE_BENCH(BM_Vlp32c, "vlp32c_fov270to90.pcap", "VLP-32C", "VLP32.calibration.yaml", false);
VELODYNE_BENCH(BM_Hdl32e, "hdl32e_example.pcap", "HDL-32E", "", false);
VELODYNE_BENCH(BM_Vls128, "vls128_strongest.pcap", "VLS-128", "VLS128.calibration.yaml", false);
VELODYNE_BENCH(BM_Vls128NebulaAzimuth, "vls128_strongest.pcap", "VLS-128", "VLS128.calibration.yaml", true);

}  // namespace
