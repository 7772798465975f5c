#include "allocation_counter.hpp"

#include <atomic>
#include <cstdlib>
#include <new>

#include "sanitizers.hpp"

namespace rigcal::test {
namespace {
std::atomic<bool> g_counting{false};
std::atomic<std::uint64_t> g_allocations{0};
}  // namespace

#if RIGCAL_TSAN
bool AllocationCounter::available() { return false; }
#else
bool AllocationCounter::available() { return true; }
#endif

void AllocationCounter::start() {
  g_allocations.store(0);
  g_counting.store(true);
}

std::uint64_t AllocationCounter::stop() {
  g_counting.store(false);
  return g_allocations.load();
}

void countAllocation() {
  if (g_counting.load(std::memory_order_relaxed)) g_allocations.fetch_add(1, std::memory_order_relaxed);
}

}  // namespace rigcal::test

#if !RIGCAL_TSAN
#if defined(__GNUC__) && !defined(__clang__)
// GCC pairs the replaced operator new with free() after inlining and warns; they do match.
#pragma GCC diagnostic ignored "-Wmismatched-new-delete"
#endif
// Replacement global allocation functions: count while enabled, otherwise plain malloc/free.
void* operator new(std::size_t n) {
  rigcal::test::countAllocation();
  if (void* p = std::malloc(n == 0 ? 1 : n)) return p;
  throw std::bad_alloc();
}
void* operator new[](std::size_t n) { return ::operator new(n); }
// The nothrow forms too (std::stable_sort's buffer uses them): every form must pair with free() below.
void* operator new(std::size_t n, const std::nothrow_t&) noexcept {
  rigcal::test::countAllocation();
  return std::malloc(n == 0 ? 1 : n);
}
void* operator new[](std::size_t n, const std::nothrow_t& tag) noexcept { return ::operator new(n, tag); }
void operator delete(void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete[](void* p, const std::nothrow_t&) noexcept { std::free(p); }
void operator delete(void* p) noexcept { std::free(p); }
void operator delete[](void* p) noexcept { std::free(p); }
void operator delete(void* p, std::size_t) noexcept { std::free(p); }
void operator delete[](void* p, std::size_t) noexcept { std::free(p); }
#endif
