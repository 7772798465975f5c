#include "rigcal/sim/recording.hpp"

#include <stdexcept>

#include "rigcal/sim/random.hpp"

namespace rigcal::sim {
namespace {

class RecordingSink : public SimulationSink {
 public:
  RecordingSink(std::vector<std::unique_ptr<PacketEncoder>> encoders, RecordingWriter& writer, SimulationSink* also)
      : encoders_(std::move(encoders)), writer_(writer), also_(also) {}

  void onFirings(std::size_t sensor, const FiringBatch& batch) override {
    encoders_[sensor]->add(batch, packets_);
    writer_.add(sensor, packets_);
    if (also_) also_->onFirings(sensor, batch);
  }
  void onScan(SimulatedScan&& scan) override {
    if (also_) also_->onScan(std::move(scan));
  }
  void onChunkEnd(TimeNs true_time) override {
    // Packets still to come carry a firing from a later chunk, so they are sent after true_time.
    writer_.flushUntil(true_time);
    if (also_) also_->onChunkEnd(true_time);
  }
  void finish() {
    for (std::size_t i = 0; i < encoders_.size(); ++i) {
      encoders_[i]->finish(packets_);
      writer_.add(i, packets_);
    }
  }

 private:
  std::vector<std::unique_ptr<PacketEncoder>> encoders_;
  RecordingWriter& writer_;
  SimulationSink* also_;
  std::vector<EncodedPacket> packets_;
};

}  // namespace

RecordingSensor recordingEndpoints(const SensorSpec& s, const LidarModel& m) {
  RecordingSensor r;
  r.source.address = ipv4FromText(s.address);
  r.source.port = s.port;
  r.source.mac = macForAddress(r.source.address);
  r.clock_offset_ns = s.clock_offset_ns;
  if (m.vendor == LidarVendor::kOuster) {
    r.destination.address = (r.source.address & 0xffffff00u) | 100u;
    r.destination.mac = macForAddress(r.destination.address);
  } else {
    r.destination.address = 0xffffffffu;
    r.destination.mac = {0xff, 0xff, 0xff, 0xff, 0xff, 0xff};
  }
  r.destination.port = s.port;
  return r;
}

std::uint16_t infoPort(const SensorSpec& s, const LidarModel& m) {
  if (m.vendor != LidarVendor::kRobosense) return 0;
  constexpr int kAfterData = 7788 - 6699;
  return std::uint16_t(s.port + kAfterData <= 65535 ? s.port + kAfterData : s.port - kAfterData);
}

std::vector<std::unique_ptr<PacketEncoder>> makeEncoders(const Simulation& sim) {
  std::vector<std::unique_ptr<PacketEncoder>> out;
  for (std::size_t i = 0; i < sim.sensorCount(); ++i) {
    const SensorSpec& s = sim.scenario().sensors[i];
    out.push_back(makePacketEncoder(sim.model(i), {s.name, s.port, false, hashKeys(sim.scenario().seed, i),
                                                   s.ouster_legacy, infoPort(s, sim.model(i))}));
  }
  return out;
}

RecordingResult writeRecording(const Simulation& sim, std::vector<std::unique_ptr<PacketEncoder>> encoders,
                               const std::filesystem::path& pcap, const SimulationOptions& options,
                               SimulationSink* also, DatagramObserver* datagrams) {
  if (encoders.size() != sim.sensorCount()) throw std::invalid_argument("writeRecording: one encoder per sensor");
  std::vector<RecordingSensor> endpoints;
  for (std::size_t i = 0; i < sim.sensorCount(); ++i) {
    if (!encoders[i]) throw std::invalid_argument("writeRecording: no packet encoder for " + sim.scenario().sensors[i].model);
    endpoints.push_back(recordingEndpoints(sim.scenario().sensors[i], sim.model(i)));
  }
  RecordingWriter writer(pcap, std::move(endpoints), hashKeys(sim.scenario().seed, 0x6e6963ULL),  // "nic"
                         datagrams);
  RecordingSink sink(std::move(encoders), writer, also);
  SimulationOptions o = options;
  o.build_scans = options.build_scans && also != nullptr;
  RecordingResult result;
  result.stats = sim.run(sink, o);
  sink.finish();
  writer.finish();
  result.datagrams = writer.datagrams();
  result.frames = writer.frames();
  return result;
}

}  // namespace rigcal::sim
