// A live RS-Helios-16P on loopback: data and DIFOP datagrams on two ports reach one decoder through
// InfoPortSource (the rig's `source: {port, info_port}`). Real sockets, real capture payloads.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <gtest/gtest.h>

#include "rigcal/drivers/info_port_source.hpp"
#include "rigcal/drivers/robosense/robosense_decoder.hpp"
#include "robosense_test_util.hpp"
#include "test_data.hpp"

namespace rigcal::drivers {
namespace {

void sendTo(int fd, std::uint16_t port, const std::vector<std::uint8_t>& payload) {
  sockaddr_in a{};
  a.sin_family = AF_INET;
  a.sin_port = htons(port);
  a.sin_addr.s_addr = htonl(0x7f000001);
  ASSERT_EQ(::sendto(fd, payload.data(), payload.size(), 0, reinterpret_cast<sockaddr*>(&a), sizeof a),
            ssize_t(payload.size()));
}

TEST(RobosenseLive, DataAndDifopPortsReachOneDecoder) {
  RIGCAL_REQUIRE_DATA(path, "robosense/helios16p.pcap");
  const auto capture = robosense_test::loadCapture(path);
  UdpSourceConfig config;
  config.bind_address = "127.0.0.1";
  InfoPortSource source(config, 0);  // both ephemeral ports
  ASSERT_NE(source.dataPort(), source.infoPort());
  const int fd = ::socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  ASSERT_GE(fd, 0);
  std::size_t sent_data = 0;
  for (std::size_t i = 0; i < capture.size() && sent_data < 40; ++i) {
    if (robosense::isDifop(capture.payloads[i])) continue;
    sendTo(fd, source.dataPort(), capture.payloads[i]);
    if (++sent_data == 20)  // the device-info packet is sent mid-stream, to its own port
      for (std::size_t j = 0; j < capture.size(); ++j)
        if (robosense::isDifop(capture.payloads[j])) sendTo(fd, source.infoPort(), capture.payloads[j]);
  }
  ::close(fd);

  DecoderConfig decoder_config;
  decoder_config.model = "RS-Helios-16P";
  RobosenseDecoder decoder(decoder_config);
  DecodedPacket out;
  std::size_t datagrams = 0, points = 0;
  while (auto p = source.next()) {
    ++datagrams;
    decoder.decode(*p, out);
    EXPECT_NE(out.kind, DecodedPacket::Kind::kMalformed) << out.error;
    points += out.points.size();
  }
  EXPECT_EQ(datagrams, 41u);
  EXPECT_TRUE(decoder.hasAngles());
  EXPECT_EQ(decoder.stats().difop_packets, 1u);
  EXPECT_GT(points, 40u * 50u) << "every data packet decoded";
}

}  // namespace
}  // namespace rigcal::drivers
