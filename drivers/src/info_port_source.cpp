#include "rigcal/drivers/info_port_source.hpp"

namespace rigcal::drivers {

UdpSourceConfig InfoPortSource::infoConfig(UdpSourceConfig config, std::uint16_t port) {
  config.port = port;
  config.filter.destination_port.reset();  // the socket's own port
  config.timeout = std::chrono::milliseconds(0);  // never wait for info: the data port paces next()
  config.batch = 4;
  config.receive_buffer_bytes = 1 << 20;
  return config;
}

InfoPortSource::InfoPortSource(const UdpSourceConfig& data, std::uint16_t info_port)
    : data_(data), info_(infoConfig(data, info_port)) {}

std::optional<UdpPacket> InfoPortSource::next() {
  if (auto info = info_.next()) return info;
  return data_.next();
}

}  // namespace rigcal::drivers
