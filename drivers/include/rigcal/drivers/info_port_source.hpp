#pragma once
// A live sensor that sends on two ports (RoboSense: MSOP data on one, DIFOP device info about once a
// second on another): one PacketSource over both. Each next() first takes a waiting datagram of the
// info port without blocking, else waits on the data port as usual, so the rare info packets reach the
// same decoder without a thread of their own. stats() are the data port's.
#include <memory>

#include "rigcal/drivers/udp_source.hpp"

namespace rigcal::drivers {

class InfoPortSource final : public PacketSource {
 public:
  /// `data` as configured; the info socket binds `info_port` with the same address, group and filter.
  InfoPortSource(const UdpSourceConfig& data, std::uint16_t info_port);
  std::optional<UdpPacket> next() override;
  [[nodiscard]] const SourceStats& stats() const override { return data_.stats(); }
  void stop() { data_.stop(), info_.stop(); }
  [[nodiscard]] std::uint16_t dataPort() const { return data_.port(); }
  [[nodiscard]] std::uint16_t infoPort() const { return info_.port(); }

 private:
  static UdpSourceConfig infoConfig(UdpSourceConfig config, std::uint16_t port);
  UdpSource data_;
  UdpSource info_;
};

}  // namespace rigcal::drivers
