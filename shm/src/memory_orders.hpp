#pragma once
// Short names for the memory orders of the ring protocol, so each load/store says its order at a glance.
#include <atomic>

namespace rigcal::shm::detail {

inline constexpr auto kRelaxed = std::memory_order_relaxed;
inline constexpr auto kAcquire = std::memory_order_acquire;
inline constexpr auto kRelease = std::memory_order_release;
inline constexpr auto kSeqCst = std::memory_order_seq_cst;

}  // namespace rigcal::shm::detail
