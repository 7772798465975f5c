#include "rigcal/drivers/udp_packet.hpp"

#include <arpa/inet.h>

#include <stdexcept>

namespace rigcal::drivers {

std::string formatIpv4(std::uint32_t address) {
  return std::to_string(address >> 24) + "." + std::to_string((address >> 16) & 0xff) + "." +
         std::to_string((address >> 8) & 0xff) + "." + std::to_string(address & 0xff);
}

std::uint32_t parseIpv4(const std::string& text) {
  in_addr addr{};
  if (inet_pton(AF_INET, text.c_str(), &addr) != 1)
    throw std::invalid_argument("'" + text + "' is not an IPv4 address");
  return ntohl(addr.s_addr);
}

}  // namespace rigcal::drivers
