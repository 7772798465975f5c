#include "rigcal/drivers/paced_source.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include "rigcal/drivers/pacing.hpp"

namespace rigcal::drivers {

PacedSource::PacedSource(PacketSource& inner, double rate, const std::atomic<bool>& stop)
    : inner_(inner), rate_(rate), stop_(stop) {
  if (!std::isfinite(rate) || rate < 0) throw std::invalid_argument("rate must be a positive number, or 0 for 'max'");
}

std::optional<UdpPacket> PacedSource::next() {
  if (stop_.load(std::memory_order_relaxed)) return std::nullopt;
  auto packet = inner_.next();
  if (!packet || rate_ == 0) return packet;
  if (!first_recorded_) {
    first_recorded_ = packet->receive_ns;
    start_wall_ = monotonicNow();
  }
  // A capture clock that steps back releases the packet at once rather than waiting.
  const TimeNs deadline = std::max(
      last_deadline_, *start_wall_ + TimeNs(double(packet->receive_ns - *first_recorded_) / rate_));
  last_deadline_ = deadline;
  if (!sleepUntil(deadline, stop_)) return std::nullopt;
  return packet;
}

}  // namespace rigcal::drivers
