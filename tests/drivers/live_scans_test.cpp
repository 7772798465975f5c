// The live path gives the same sweeps as the offline path: a real capture replayed at its recorded
// rate over loopback UDP into UdpSource, decoded with the sensor clock, equals decoding the pcap.
#include <gtest/gtest.h>

#include <atomic>
#include <thread>

#include "rigcal/drivers/pcap_replayer.hpp"
#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/drivers/scan_pump.hpp"
#include "rigcal/drivers/udp_source.hpp"
#include "test_data.hpp"

namespace rigcal::drivers {
namespace {

std::vector<Scan> decodeAll(PacketSource& source, const DecoderConfig& config,
                            const std::function<bool(bool)>& keep_going = {}) {
  std::vector<Scan> scans;
  auto decoder = makeDecoder(config);
  ScanAssembler assembler(config.model, AssemblerConfig{}, [&](Scan&& s) { scans.push_back(std::move(s)); });
  pumpScans(source, *decoder, assembler, keep_going);
  return scans;
}

// `clock_period_ns`: a sensor clock that only counts within a period (Velodyne: µs past the hour) takes
// the rest from the receive time, which differs between the live run and the capture.
void expectSameScans(const std::vector<Scan>& live, const std::vector<Scan>& offline, TimeNs clock_period_ns) {
  ASSERT_EQ(live.size(), offline.size());
  for (std::size_t i = 0; i < live.size(); ++i) {
    if (clock_period_ns)
      EXPECT_EQ(live[i].stamp_ns % clock_period_ns, offline[i].stamp_ns % clock_period_ns) << "scan " << i;
    else
      EXPECT_EQ(live[i].stamp_ns, offline[i].stamp_ns) << "scan " << i;
    EXPECT_EQ(live[i].x, offline[i].x) << "scan " << i;
    EXPECT_EQ(live[i].y, offline[i].y) << "scan " << i;
    EXPECT_EQ(live[i].z, offline[i].z) << "scan " << i;
    EXPECT_EQ(live[i].offset_ns, offline[i].offset_ns) << "scan " << i;
    EXPECT_EQ(live[i].missing_packets, 0u);
  }
}

void replayAndCompare(const std::filesystem::path& capture, std::uint16_t port, const DecoderConfig& config,
                      TimeNs clock_period_ns = 0) {
  PcapSource offline_source(capture, PacketFilter{port, std::nullopt});
  const std::vector<Scan> offline = decodeAll(offline_source, config);
  ASSERT_GT(offline.size(), 0u);

  UdpSourceConfig listen;
  listen.bind_address = "127.0.0.1";
  listen.timeout = std::chrono::milliseconds(300);
  UdpSource live_source(listen);
  ReplayConfig replay;
  replay.rate = 1.0;
  replay.filter.destination_port = port;
  replay.port_offset = int(live_source.port()) - int(port);
  PcapReplayer replayer(capture, replay);
  std::atomic<bool> sent{false};
  std::thread sender([&] {
    replayer.run();
    sent = true;
  });
  // Read until the replay is over and the socket has then gone quiet for one timeout.
  const std::vector<Scan> live = decodeAll(live_source, config, [&](bool idle) { return !(idle && sent.load()); });
  sender.join();
  EXPECT_EQ(live_source.stats().kernel_drops, 0u);
  expectSameScans(live, offline, clock_period_ns);
}

TEST(LiveScans, VelodyneReplayedOverLoopbackEqualsOfflineDecode) {
  RIGCAL_REQUIRE_DATA(capture, "velodyne/vlp16_dual.pcap");
  DecoderConfig config;
  config.model = "VLP-16";
  replayAndCompare(capture, 2368, config, 3600 * kNsPerSec);
}

TEST(LiveScans, OusterFragmentedPacketsReplayedOverLoopbackEqualOfflineDecode) {
  RIGCAL_REQUIRE_DATA(capture, "ouster/OS-1-32-G_v2.1.1_1024x10.pcap");
  DecoderConfig config;
  config.model = "Ouster";
  config.metadata = test::dataDir() / "ouster/OS-1-32-G_v2.1.1_1024x10.json";
  replayAndCompare(capture, 7502, config);
}

TEST(LiveScans, HesaiReplayedOverLoopbackEqualsOfflineDecode) {
  RIGCAL_REQUIRE_DATA(capture, "hesai/xt16_dual.pcap");
  DecoderConfig config;
  config.model = "PandarXT16";
  config.calibration = test::dataDir() / "hesai/PandarXT16.csv";
  replayAndCompare(capture, 2368, config);
}

}  // namespace
}  // namespace rigcal::drivers
