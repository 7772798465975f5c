#pragma once
// Where a firing goes in the packet being filled. Every vendor's data packet holds a fixed number of
// consecutive firing sequences (blocks): a packet starts at its first slot, and a sequence out of line
// (a simulated outage) drops the packet in progress instead of sending a torn one.
#include <cstdint>

#include "encoder_util.hpp"

namespace rigcal::sim::encoders {

class PacketSlots {
 public:
  explicit PacketSlots(int slots_per_packet) : slots_(slots_per_packet) {}

  /// The slot of `sequence` in the packet in progress, 0 when it starts a new packet (packetIndex() is
  /// then its index), or -1 when it cannot be placed (mid-packet with no packet in progress).
  int place(std::int64_t sequence) {
    const std::int64_t index = floorDivNs(sequence, slots_);
    const int slot = int(sequence - index * slots_);
    if (filled_ >= 0 && (index != index_ || slot != filled_)) filled_ = -1;
    if (filled_ < 0) {
      if (slot != 0) return -1;  // wait for the next packet boundary
      index_ = index;
      filled_ = 0;
    }
    return slot;
  }
  /// The placed slot is written; true when that completed the packet (the next one starts afresh).
  bool written() {
    if (++filled_ < slots_) return false;
    filled_ = -1;
    return true;
  }
  /// Drops the packet in progress (at the end of a recording a partial packet is never sent).
  void reset() { filled_ = -1; }
  [[nodiscard]] std::int64_t packetIndex() const { return index_; }

 private:
  int slots_;
  std::int64_t index_ = 0;
  int filled_ = -1;  // slots written into the packet in progress; -1: none in progress
};

}  // namespace rigcal::sim::encoders
