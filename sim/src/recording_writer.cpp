#include "rigcal/sim/recording_writer.hpp"

#include <algorithm>
#include <limits>

namespace rigcal::sim {

TimeNs datagramWireTimeNs(std::size_t payload_bytes) {
  const std::size_t ip_payload = payload_bytes + 8, per_fragment = 1480;
  TimeNs t = 0;
  for (std::size_t off = 0; off < ip_payload; off += per_fragment)
    t += wireTimeNs(14 + 20 + std::min(per_fragment, ip_payload - off));
  return t;
}

RecordingWriter::RecordingWriter(const std::filesystem::path& file, std::vector<RecordingSensor> sensors,
                                 std::uint64_t seed, DatagramObserver* observer)
    : observer_(observer), sensors_(std::move(sensors)), nic_(seed) {
  if (!file.empty()) pcap_.emplace(file);
}

void RecordingWriter::add(std::size_t sensor, std::vector<EncodedPacket>& packets) {
  for (auto& p : packets)
    queue_.push({p.send_time_ns - sensors_.at(sensor).clock_offset_ns, sensor, order_++, p.destination_port,
                 std::move(p.payload)});
  packets.clear();
}

void RecordingWriter::flushUntil(TimeNs true_time) {
  while (!queue_.empty() && queue_.top().send_true_ns < true_time) {
    const Pending& p = queue_.top();
    const RecordingSensor& s = sensors_[p.sensor];
    const TimeNs stamp = nic_.stamp(p.send_true_ns, datagramWireTimeNs(p.payload.size()));
    NetEndpoint destination = s.destination;
    if (p.port != 0) destination.port = p.port;
    if (pcap_) pcap_->writeDatagram(s.source, destination, p.payload, stamp);
    if (observer_) observer_->onDatagram(p.sensor, destination.port, p.payload, stamp);
    ++datagrams_;
    queue_.pop();
  }
}

void RecordingWriter::finish() {
  flushUntil(std::numeric_limits<TimeNs>::max());
  if (pcap_) pcap_->close();
}

}  // namespace rigcal::sim
