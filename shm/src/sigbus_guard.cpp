#include "sigbus_guard.hpp"

#include <sys/mman.h>

#include <atomic>
#include <csignal>
#include <cstdint>
#include <mutex>

namespace rigcal::shm::detail {
namespace {

struct Shield {
  std::atomic<std::uintptr_t> base{0};  // 0: free
  std::atomic<std::size_t> bytes{0};
  std::atomic<bool> tripped{false};
};

Shield g_shields[TruncationShield::kMaxShields];
struct sigaction g_previous {};
std::once_flag g_installed;

void onSigbus(int signal, siginfo_t* info, void* context) {
  const auto addr = reinterpret_cast<std::uintptr_t>(info->si_addr);
  for (Shield& s : g_shields) {
    const std::uintptr_t base = s.base.load(std::memory_order_acquire);
    const std::size_t bytes = s.bytes.load(std::memory_order_acquire);
    if (base == 0 || addr < base || addr >= base + bytes) continue;
    // Zero pages in place of the truncated file's: the faulting access is retried on them.
    if (::mmap(reinterpret_cast<void*>(base), bytes, PROT_READ | PROT_WRITE, MAP_FIXED | MAP_PRIVATE | MAP_ANONYMOUS,
               -1, 0) == MAP_FAILED)
      break;
    s.tripped.store(true, std::memory_order_release);
    return;
  }
  // Not ours: what was there before (the default kills the process); the faulting access repeats under it.
  if ((g_previous.sa_flags & SA_SIGINFO) != 0 && g_previous.sa_sigaction != nullptr) {
    g_previous.sa_sigaction(signal, info, context);
    return;
  }
  ::sigaction(SIGBUS, &g_previous, nullptr);
}

void install() {
  struct sigaction sa {};
  sa.sa_sigaction = onSigbus;
  sa.sa_flags = SA_SIGINFO;
  sigemptyset(&sa.sa_mask);
  ::sigaction(SIGBUS, &sa, &g_previous);
}

}  // namespace

TruncationShield::TruncationShield(void* base, std::size_t bytes) {
  std::call_once(g_installed, install);
  for (int i = 0; i < kMaxShields; ++i) {
    std::uintptr_t free = 0;
    Shield& s = g_shields[i];
    // A free slot has bytes 0: claimed with its base first, it matches no address until its size is set.
    if (!s.base.compare_exchange_strong(free, reinterpret_cast<std::uintptr_t>(base), std::memory_order_acq_rel))
      continue;
    s.tripped.store(false, std::memory_order_release);
    s.bytes.store(bytes, std::memory_order_release);
    slot_ = i;
    return;
  }
}

TruncationShield::~TruncationShield() {
  if (slot_ < 0) return;
  g_shields[slot_].bytes.store(0, std::memory_order_release);
  g_shields[slot_].base.store(0, std::memory_order_release);
}

bool TruncationShield::tripped() const {
  return slot_ >= 0 && g_shields[slot_].tripped.load(std::memory_order_acquire);
}

}  // namespace rigcal::shm::detail
