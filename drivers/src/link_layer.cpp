#include "rigcal/drivers/link_layer.hpp"

namespace rigcal::drivers {
namespace {

std::uint16_t be16(const std::uint8_t* p) { return std::uint16_t(p[0] << 8 | p[1]); }
std::uint32_t be32(const std::uint8_t* p) {
  return std::uint32_t(p[0]) << 24 | std::uint32_t(p[1]) << 16 | std::uint32_t(p[2]) << 8 | p[3];
}

constexpr std::uint16_t kEtherIpv4 = 0x0800;
constexpr std::uint16_t kEtherVlan = 0x8100;
constexpr std::uint16_t kEtherQinQ = 0x88a8;

FrameResult parseIpv4(std::span<const std::uint8_t> b, Ipv4Header& out) {
  if (b.size() < 20) return FrameResult::kMalformed;
  if ((b[0] >> 4) != 4) return FrameResult::kNotIpv4;
  const std::size_t header_len = std::size_t(b[0] & 0x0f) * 4;
  const std::size_t total_len = be16(&b[2]);
  // Total length 0 (TSO captures) means "the captured size". A total length beyond the captured bytes
  // is clamped: VLP-16 position packets declare 1234 bytes but carry 540, and their UDP length is right.
  const std::size_t end = (total_len == 0 || total_len > b.size()) ? b.size() : total_len;
  if (header_len < 20 || end < header_len) return FrameResult::kMalformed;
  out.identification = be16(&b[4]);
  const std::uint16_t flags_frag = be16(&b[6]);
  out.more_fragments = flags_frag & 0x2000;
  out.fragment_offset = std::uint16_t((flags_frag & 0x1fff) * 8);
  out.protocol = b[9];
  out.source = be32(&b[12]);
  out.destination = be32(&b[16]);
  out.payload = b.subspan(header_len, end - header_len);
  return FrameResult::kIpv4;
}

}  // namespace

FrameResult parseFrame(LinkType link, std::span<const std::uint8_t> frame, Ipv4Header& out) {
  std::size_t offset = 0;
  std::uint16_t ether_type = 0;
  switch (link) {
    case LinkType::kEthernet: {
      if (frame.size() < 14) return FrameResult::kMalformed;
      ether_type = be16(&frame[12]);
      offset = 14;
      while (ether_type == kEtherVlan || ether_type == kEtherQinQ) {
        if (frame.size() < offset + 4) return FrameResult::kMalformed;
        ether_type = be16(&frame[offset + 2]);
        offset += 4;
      }
      break;
    }
    case LinkType::kLinuxSll:
      if (frame.size() < 16) return FrameResult::kMalformed;
      ether_type = be16(&frame[14]);
      offset = 16;
      break;
    case LinkType::kLinuxSll2:
      if (frame.size() < 20) return FrameResult::kMalformed;
      ether_type = be16(&frame[0]);
      offset = 20;
      break;
    case LinkType::kRaw:
    case LinkType::kIpv4:
      return parseIpv4(frame, out);
  }
  if (ether_type != kEtherIpv4) return FrameResult::kNotIpv4;
  return parseIpv4(frame.subspan(offset), out);
}

std::optional<UdpHeader> parseUdp(std::span<const std::uint8_t> d) {
  if (d.size() < 8) return std::nullopt;
  const std::size_t length = be16(&d[4]);
  // Length 0 happens with UDP over jumbo/TSO captures; trust the datagram then.
  const std::size_t end = length == 0 ? d.size() : length;
  if (end < 8 || end > d.size()) return std::nullopt;
  return UdpHeader{be16(&d[0]), be16(&d[2]), d.subspan(8, end - 8)};
}

}  // namespace rigcal::drivers
