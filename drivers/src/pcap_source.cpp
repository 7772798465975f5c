#include "rigcal/drivers/pcap_source.hpp"

#include <pcap/pcap.h>

#include <stdexcept>

namespace rigcal::drivers {

namespace {
constexpr std::uint8_t kProtocolUdp = 17;
}

PcapSource::PcapSource(const std::filesystem::path& file, PacketFilter filter)
    : file_(file), filter_(filter) {
  char err[PCAP_ERRBUF_SIZE] = {};
  handle_ = pcap_open_offline_with_tstamp_precision(file.c_str(), PCAP_TSTAMP_PRECISION_NANO, err);
  if (!handle_) throw std::runtime_error(file.string() + ": cannot read capture: " + err);
  const int dlt = pcap_datalink(handle_);
  switch (dlt) {
    case DLT_EN10MB: link_ = LinkType::kEthernet; break;
    case DLT_RAW: link_ = LinkType::kRaw; break;
    case DLT_LINUX_SLL: link_ = LinkType::kLinuxSll; break;
    case DLT_LINUX_SLL2: link_ = LinkType::kLinuxSll2; break;
    case DLT_IPV4: link_ = LinkType::kIpv4; break;
    default:
      pcap_close(handle_);
      handle_ = nullptr;
      throw std::runtime_error(file.string() + ": unsupported link type " + std::to_string(dlt) +
                               " (Ethernet, Linux cooked and raw IPv4 are read)");
  }
}

PcapSource::~PcapSource() {
  if (handle_) pcap_close(handle_);
}

std::optional<UdpPacket> PcapSource::next() {
  while (handle_) {
    pcap_pkthdr* header = nullptr;
    const std::uint8_t* data = nullptr;
    const int rc = pcap_next_ex(handle_, &header, &data);
    if (rc == PCAP_ERROR_BREAK) return std::nullopt;  // clean end of file
    if (rc != 1) {
      // libpcap reports a record cut short by the end of the file as an error: keep what came before.
      warning_ = file_.string() + ": capture ends inside a record (" + pcap_geterr(handle_) +
                 "); kept the " + std::to_string(stats_.packets) + " datagrams before it";
      return std::nullopt;
    }

    Ipv4Header ip;
    const auto frame = std::span<const std::uint8_t>(data, header->caplen);
    const FrameResult fr = parseFrame(link_, frame, ip);
    if (fr == FrameResult::kMalformed) {
      ++stats_.malformed;
      continue;
    }
    if (fr == FrameResult::kNotIpv4 || ip.protocol != kProtocolUdp) {
      ++stats_.not_udp;
      continue;
    }
    std::span<const std::uint8_t> datagram = ip.payload;
    if (ip.more_fragments || ip.fragment_offset != 0) {
      datagram = reassembler_.add(ip);
      stats_.fragments_dropped = reassembler_.dropped();
      if (datagram.empty()) continue;
    }
    const auto udp = parseUdp(datagram);
    if (!udp) {
      ++stats_.malformed;
      continue;
    }
    UdpPacket packet;
    packet.payload = udp->payload;
    // Opened with nanosecond precision: tv_usec holds nanoseconds.
    packet.receive_ns = TimeNs(header->ts.tv_sec) * kNsPerSec + TimeNs(header->ts.tv_usec);
    packet.source = {ip.source, udp->source_port};
    packet.destination = {ip.destination, udp->destination_port};
    if (!filter_.accepts(packet)) {
      ++stats_.filtered;
      continue;
    }
    ++stats_.packets;
    return packet;
  }
  return std::nullopt;
}

}  // namespace rigcal::drivers
