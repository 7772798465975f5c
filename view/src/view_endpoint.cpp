#include "rigcal/view/view_endpoint.hpp"

#include <boost/asio/ip/address.hpp>
#include <charconv>
#include <stdexcept>

namespace rigcal::view {

bool ViewEndpoint::loopback() const {
  boost::system::error_code ec;
  const auto a = boost::asio::ip::make_address(address, ec);
  return !ec && a.is_loopback();
}

ViewEndpoint parseViewEndpoint(std::string_view spec) {
  const auto bad = [&](const std::string& why) {
    return std::invalid_argument("--view '" + std::string(spec) + "': " + why + " (expected [ADDR:]PORT, e.g. 8080 or 0.0.0.0:8080)");
  };
  ViewEndpoint e;
  std::string_view port = spec;
  if (const auto colon = spec.rfind(':'); colon != std::string_view::npos) {
    std::string_view addr = spec.substr(0, colon);
    port = spec.substr(colon + 1);
    if (addr.size() >= 2 && addr.front() == '[' && addr.back() == ']') addr = addr.substr(1, addr.size() - 2);
    boost::system::error_code ec;
    boost::asio::ip::make_address(std::string(addr), ec);
    if (ec) throw bad("'" + std::string(addr) + "' is not an IP address");
    e.address = std::string(addr);
  }
  unsigned value = 0;
  const auto [end, err] = std::from_chars(port.data(), port.data() + port.size(), value);
  if (port.empty() || err != std::errc() || end != port.data() + port.size() || value > 65535)
    throw bad("the port must be a number 0-65535");
  e.port = static_cast<std::uint16_t>(value);
  return e;
}

}  // namespace rigcal::view
