#include "rigcal/sim/pcap_writer.hpp"

#include <algorithm>
#include <stdexcept>
#include <string>

namespace rigcal::sim {
namespace {

constexpr std::size_t kEthernetHeader = 14, kIpv4Header = 20, kUdpHeader = 8;
constexpr std::size_t kMinFrame = 60;  // Ethernet minimum without FCS: short frames are padded

void put16(std::vector<std::uint8_t>& b, std::size_t at, std::uint16_t v) {  // network order
  b[at] = std::uint8_t(v >> 8);
  b[at + 1] = std::uint8_t(v);
}
void put32(std::vector<std::uint8_t>& b, std::size_t at, std::uint32_t v) {
  put16(b, at, std::uint16_t(v >> 16));
  put16(b, at + 2, std::uint16_t(v));
}
void le32(std::ostream& out, std::uint32_t v) {  // pcap headers: little-endian
  const char b[4] = {char(v), char(v >> 8), char(v >> 16), char(v >> 24)};
  out.write(b, 4);
}
void le16(std::ostream& out, std::uint16_t v) {
  const char b[2] = {char(v), char(v >> 8)};
  out.write(b, 2);
}

std::uint16_t ipv4Checksum(const std::uint8_t* header) {
  std::uint32_t sum = 0;
  for (std::size_t i = 0; i < kIpv4Header; i += 2) sum += std::uint32_t(header[i] << 8 | header[i + 1]);
  while (sum >> 16) sum = (sum & 0xffff) + (sum >> 16);
  return std::uint16_t(~sum);
}

}  // namespace

std::uint32_t ipv4FromText(const std::string& text) {
  std::uint32_t out = 0;
  int parts = 0;
  std::size_t i = 0;
  while (parts < 4) {
    std::size_t j = i;
    unsigned value = 0;
    while (j < text.size() && text[j] >= '0' && text[j] <= '9' && j - i < 3) value = value * 10 + unsigned(text[j++] - '0');
    if (j == i || value > 255) break;
    out = out << 8 | value;
    ++parts;
    if (parts < 4) {
      if (j >= text.size() || text[j] != '.') break;
      ++j;
    }
    i = j;
  }
  if (parts != 4 || i != text.size()) throw std::invalid_argument("'" + text + "' is not an IPv4 address");
  return out;
}

MacAddress macForAddress(std::uint32_t a) {
  return {0x02, 0x00, std::uint8_t(a >> 24), std::uint8_t(a >> 16), std::uint8_t(a >> 8), std::uint8_t(a)};
}

TimeNs wireTimeNs(std::size_t bytes) {
  // 8 bytes preamble + 4 FCS + 12 inter-frame gap; 1 Gbit/s = 8 ns per byte.
  return TimeNs(std::max(bytes, kMinFrame) + 24) * 8;
}

PcapWriter::PcapWriter(const std::filesystem::path& file, Options options)
    : file_(file), options_(options), file_out_(std::make_unique<AtomicFile>(file)), out_(file_out_->stream()) {
  if (options_.mtu < 68 || (options_.mtu - kIpv4Header) % 8 != 0)
    throw std::invalid_argument("pcap writer: the MTU minus the IPv4 header must be a multiple of 8");
  le32(out_, 0xa1b23c4d);  // nanosecond-resolution pcap
  le16(out_, 2);
  le16(out_, 4);
  le32(out_, 0);  // thiszone
  le32(out_, 0);  // sigfigs
  le32(out_, options_.snaplen);
  le32(out_, 1);  // LINKTYPE_ETHERNET
}

void PcapWriter::writeFrame(std::span<const std::uint8_t> frame, TimeNs capture_ns) {
  if (capture_ns < 0) throw std::invalid_argument("pcap writer: negative capture time");
  const std::uint32_t captured = std::uint32_t(std::min<std::size_t>(frame.size(), options_.snaplen));
  le32(out_, std::uint32_t(capture_ns / kNsPerSec));
  le32(out_, std::uint32_t(capture_ns % kNsPerSec));
  le32(out_, captured);
  le32(out_, std::uint32_t(frame.size()));
  out_.write(reinterpret_cast<const char*>(frame.data()), std::streamsize(captured));
  ++frames_;
}

TimeNs PcapWriter::writeDatagram(const NetEndpoint& source, const NetEndpoint& destination,
                                 std::span<const std::uint8_t> payload, TimeNs capture_ns) {
  const std::size_t udp_length = kUdpHeader + payload.size();
  if (udp_length > 65535 - kIpv4Header) throw std::invalid_argument("pcap writer: UDP payload too large");
  const std::uint16_t id = next_id_[source.address]++;
  const std::size_t max_fragment = options_.mtu - kIpv4Header;  // a multiple of 8
  // The IP payload: the UDP header followed by the data; fragments cut through it.
  std::vector<std::uint8_t> udp(udp_length);
  put16(udp, 0, source.port);
  put16(udp, 2, destination.port);
  put16(udp, 4, std::uint16_t(udp_length));
  put16(udp, 6, 0);  // no checksum
  std::copy(payload.begin(), payload.end(), udp.begin() + kUdpHeader);

  TimeNs t = capture_ns;
  for (std::size_t offset = 0; offset < udp_length; offset += max_fragment) {
    const std::size_t chunk = std::min(max_fragment, udp_length - offset);
    const bool more = offset + chunk < udp_length;
    const std::size_t length = kEthernetHeader + kIpv4Header + chunk;
    frame_.assign(std::max(length, kMinFrame), 0);
    std::copy(destination.mac.begin(), destination.mac.end(), frame_.begin());
    std::copy(source.mac.begin(), source.mac.end(), frame_.begin() + 6);
    put16(frame_, 12, 0x0800);
    const std::size_t ip = kEthernetHeader;
    frame_[ip] = 0x45;
    frame_[ip + 1] = 0;
    put16(frame_, ip + 2, std::uint16_t(kIpv4Header + chunk));
    put16(frame_, ip + 4, id);
    put16(frame_, ip + 6, std::uint16_t((more ? 0x2000 : 0) | (offset / 8)));
    frame_[ip + 8] = 64;  // TTL
    frame_[ip + 9] = 17;  // UDP
    put32(frame_, ip + 12, source.address);
    put32(frame_, ip + 16, destination.address);
    put16(frame_, ip + 10, ipv4Checksum(&frame_[ip]));
    std::copy(udp.begin() + std::ptrdiff_t(offset), udp.begin() + std::ptrdiff_t(offset + chunk),
              frame_.begin() + std::ptrdiff_t(ip + kIpv4Header));
    writeFrame(frame_, t);
    if (more) t += wireTimeNs(frame_.size());
  }
  return t;
}

void PcapWriter::close() {
  file_out_->commit();
}

TimeNs NicClock::stamp(TimeNs send_ns, TimeNs wire_ns) {
  const TimeNs jitter = TimeNs(rng_.uniform() * double(jitter_));
  const TimeNs t = std::max(send_ns + latency_ + jitter, free_at_);
  free_at_ = t + wire_ns;
  return t;
}

}  // namespace rigcal::sim
