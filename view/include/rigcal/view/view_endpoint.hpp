#pragma once
// Where the live view listens: `--view [ADDR:]PORT`. Loopback unless an address is given.
#include <cstdint>
#include <string>
#include <string_view>

namespace rigcal::view {

struct ViewEndpoint {
  std::string address = "127.0.0.1";
  std::uint16_t port = 0;  // 0: any free port (tests)
  /// True for 127.0.0.0/8 and ::1: reachable from this machine only.
  [[nodiscard]] bool loopback() const;
};

/// "8080", "127.0.0.1:8080", "0.0.0.0:8080", "[::1]:8080". Throws std::invalid_argument (one line naming
/// the value) for anything else.
ViewEndpoint parseViewEndpoint(std::string_view spec);

}  // namespace rigcal::view
