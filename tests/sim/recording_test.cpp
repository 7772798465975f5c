// The capture path end to end, with a test-only encoder (not a vendor format: it just serialises the
// sequence numbers it was given), so merging, clock offsets, NIC stamps and fragmentation are
// checked independently of the vendor encoders.
#include <gtest/gtest.h>

#include <cstring>
#include <map>

#include "rigcal/drivers/pcap_source.hpp"
#include "rigcal/sim/recording.hpp"
#include "test_data.hpp"

namespace rigcal::sim {
namespace {

using rigcal::test::TempDir;

class SequenceEncoder : public PacketEncoder {
 public:
  SequenceEncoder(std::uint8_t sensor, std::size_t per_packet, std::size_t padding)
      : sensor_(sensor), per_packet_(per_packet), padding_(padding) {}
  void add(const FiringBatch& batch, std::vector<EncodedPacket>& out) override {
    for (const SimFiring& f : batch.firings) {
      pending_.push_back(f.sequence);
      last_time_ = f.sensor_time_ns;
      if (pending_.size() == per_packet_) emit(out);
    }
  }
  void finish(std::vector<EncodedPacket>& out) override {
    if (!pending_.empty()) emit(out);
  }
  [[nodiscard]] std::string model() const override { return "test"; }

 private:
  void emit(std::vector<EncodedPacket>& out) {
    EncodedPacket p;
    p.payload.assign(1 + 8 * pending_.size() + padding_, 0);
    p.payload[0] = sensor_;
    std::memcpy(p.payload.data() + 1, pending_.data(), 8 * pending_.size());
    p.send_time_ns = last_time_ + 100'000;  // sent 100 µs after its last firing (sensor clock)
    out.push_back(std::move(p));
    pending_.clear();
  }
  std::uint8_t sensor_;
  std::size_t per_packet_, padding_;
  std::vector<std::int64_t> pending_;
  TimeNs last_time_ = 0;
};

TEST(Recording, EveryFiringReachesTheCaptureInOrderFromItsOwnSource) {
  const std::string text = R"(
scenario: rec
rig:
  mapping_lidar: a
  sensors:
    - {name: a, model: OS1-64, address: 10.5.5.87, port: 7502, extrinsic: {z: 2}}
    - {name: b, model: VLP-16, address: 192.168.1.201, port: 2368, extrinsic: {x: 2, z: 1}, clock_offset_ms: 3.0}
scene: {layout: empty}
trajectory: {segments: [{type: stop, duration: 0.3}]}
)";
  const Simulation sim(parseScenario(text, "rec"));
  std::vector<std::unique_ptr<PacketEncoder>> enc;
  enc.push_back(std::make_unique<SequenceEncoder>(0, 16, 6000));  // Ouster-sized: fragmented
  enc.push_back(std::make_unique<SequenceEncoder>(1, 24, 1000));
  TempDir dir;
  SimulationOptions o;
  o.chunk_ns = 20 * kNsPerMs;
  const RecordingResult r = writeRecording(sim, std::move(enc), dir / "rec.pcap", o);
  EXPECT_GT(r.frames, r.datagrams) << "the 6 kB datagrams are fragmented";

  drivers::PcapSource source(dir / "rec.pcap");
  std::map<int, std::int64_t> next_seq;
  std::map<int, std::size_t> firings;
  TimeNs last = 0;
  std::size_t datagrams = 0;
  while (auto p = source.next()) {
    ++datagrams;
    const int s = p->payload[0];
    EXPECT_EQ(p->source.address, ipv4FromText(s == 0 ? "10.5.5.87" : "192.168.1.201"));
    EXPECT_EQ(p->destination.port, s == 0 ? 7502 : 2368);
    EXPECT_GE(p->receive_ns, last) << "capture stamps are monotonic";
    last = p->receive_ns;
    const std::size_t n = (p->payload.size() - 1 - (s == 0 ? 6000 : 1000)) / 8;
    for (std::size_t k = 0; k < n; ++k) {
      std::int64_t seq = 0;
      std::memcpy(&seq, p->payload.data() + 1 + 8 * k, 8);
      if (next_seq.count(s)) {
        EXPECT_EQ(seq, next_seq[s]) << "sensor " << s << ": in order, nothing lost";
      }
      next_seq[s] = seq + 1;
      ++firings[s];
    }
  }
  EXPECT_EQ(datagrams, r.datagrams);
  EXPECT_EQ(source.stats().fragments_dropped, 0u);
  EXPECT_EQ(firings[0] + firings[1], r.stats.firings);
  EXPECT_NEAR(double(firings[0]), 0.3 * 10240, 2);
  EXPECT_NEAR(double(firings[1]), 0.3 * 1e9 / 55296, 2);
  EXPECT_GE(last, sim.startTime() + fromSeconds(0.3) - 3 * kNsPerMs);
}

TEST(Recording, RefusesMissingEncoders) {
  const Simulation sim(loadScenario("pose"));
  auto encoders = makeEncoders(sim);
  ASSERT_EQ(encoders.size(), 1u);
  encoders[0].reset();  // as if its model had no encoder
  TempDir dir;
  EXPECT_THROW(writeRecording(sim, std::move(encoders), dir / "x.pcap", {}), std::invalid_argument);
  EXPECT_FALSE(std::filesystem::exists(dir / "x.pcap"));
}

}  // namespace
}  // namespace rigcal::sim
