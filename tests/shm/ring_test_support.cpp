#include "ring_test_support.hpp"

#include <unistd.h>

#include <cstdlib>
#include <new>

#include "rigcal/shm/ring_segment.hpp"

namespace rigcal::shm::test {

UniquePrefix::UniquePrefix() {
  static std::atomic<int> counter{0};
  prefix_ = "rigcal-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++) + ".";
  for (const auto& s : segments()) removeSegment(s);
}

UniquePrefix::~UniquePrefix() {
  for (const auto& s : segments()) removeSegment(s);
}

std::vector<std::string> UniquePrefix::segments() const { return listSegments(prefix_); }

std::string peerPath() { return RIGCAL_RING_PEER; }

namespace {
std::atomic<bool> g_counting{false};
std::atomic<std::uint64_t> g_allocations{0};
}  // namespace

void AllocationCounter::start() {
  g_allocations.store(0);
  g_counting.store(true);
}

std::uint64_t AllocationCounter::stop() {
  g_counting.store(false);
  return g_allocations.load();
}

}  // namespace rigcal::shm::test

// Replacement global allocation functions: count while enabled, otherwise plain malloc/free.
void* operator new(std::size_t n) {
  if (rigcal::shm::test::g_counting.load(std::memory_order_relaxed)) {
    rigcal::shm::test::g_allocations.fetch_add(1, std::memory_order_relaxed);
  }
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return ::operator new(n); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
