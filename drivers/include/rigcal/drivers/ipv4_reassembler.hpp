#pragma once
// Reassembles fragmented IPv4 datagrams (Ouster lidar packets exceed the 1500-byte MTU). Bounded:
// at most `max_pending` datagrams in flight; the oldest incomplete one is dropped and counted.
#include <cstdint>
#include <deque>
#include <span>
#include <vector>

#include "rigcal/drivers/link_layer.hpp"

namespace rigcal::drivers {

class Ipv4Reassembler {
 public:
  explicit Ipv4Reassembler(std::size_t max_pending = 32) : max_pending_(max_pending) {}

  /// Feeds one fragment; returns the whole IP payload once every byte has arrived, else empty.
  /// The returned span stays valid until the next call.
  std::span<const std::uint8_t> add(const Ipv4Header& fragment);
  [[nodiscard]] std::uint64_t dropped() const { return dropped_; }

 private:
  struct Pending {
    std::uint32_t source, destination;
    std::uint16_t identification;
    std::uint8_t protocol;
    std::vector<std::uint8_t> data;
    std::vector<bool> have;      // per 8-byte block
    std::size_t total = 0;       // known once the last fragment arrived
    std::size_t received = 0;    // bytes received (overlaps counted once)
  };
  std::size_t max_pending_;
  std::deque<Pending> pending_;
  std::vector<std::uint8_t> done_;
  std::uint64_t dropped_ = 0;
};

}  // namespace rigcal::drivers
