#pragma once
// Replays a recorded source (a pcap) at its recorded timing, scaled by a rate: what a driver reading a
// capture "live" needs. rate 0 passes datagrams through as fast as they come.
#include <atomic>
#include <optional>

#include "rigcal/drivers/packet_source.hpp"

namespace rigcal::drivers {

class PacedSource final : public PacketSource {
 public:
  /// `inner` and `stop` must outlive this; next() returns nullopt early once `stop` is set.
  PacedSource(PacketSource& inner, double rate, const std::atomic<bool>& stop);
  std::optional<UdpPacket> next() override;
  [[nodiscard]] const SourceStats& stats() const override { return inner_.stats(); }
  [[nodiscard]] std::string warning() const override { return inner_.warning(); }

 private:
  PacketSource& inner_;
  double rate_;
  const std::atomic<bool>& stop_;
  std::optional<TimeNs> first_recorded_, start_wall_;
  TimeNs last_deadline_ = 0;
};

}  // namespace rigcal::drivers
