#pragma once
// A reader maps a ring whose size another process (of the ring's owner: the mode is 0600) can cut at any
// moment. The fstat check before each read (ScanRingReader::Impl::requireIntact) leaves a window: a
// truncation after it makes the next touched page past the new end raise SIGBUS, which kills the process
// (a slot copy, the header's liveness fields, the reader's own record: any of them).
//
// A TruncationShield makes that impossible for one mapping: on a SIGBUS inside it, the handler replaces the
// whole mapping with private zero pages (mmap MAP_FIXED, async-signal-safe) and returns, so the faulting
// access and everything after it read zeros, which the ring protocol already treats as nothing published
// (sequence 0: a torn read; write index 0: empty; no writer). The next size check reports the truncation.
// A SIGBUS outside every shielded mapping keeps the disposition it had (default: the process dies).
#include <cstddef>

namespace rigcal::shm::detail {

class TruncationShield {
 public:
  /// Shields [base, base + bytes) until destroyed (at most kMaxShields at a time; beyond that, unshielded).
  TruncationShield(void* base, std::size_t bytes);
  ~TruncationShield();
  TruncationShield(const TruncationShield&) = delete;
  TruncationShield& operator=(const TruncationShield&) = delete;

  /// True once a SIGBUS replaced the mapping with zero pages.
  [[nodiscard]] bool tripped() const;
  [[nodiscard]] bool active() const { return slot_ >= 0; }

  static constexpr int kMaxShields = 64;

 private:
  int slot_ = -1;
};

}  // namespace rigcal::shm::detail
