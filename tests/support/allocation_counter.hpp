#pragma once
// Counts heap allocations (global operator new) between start() and stop(), to show that a hot path
// allocates nothing in steady state. Link rigcal_test_allocations to use it. Under ThreadSanitizer the
// sanitizer runtime owns operator new, so counting is unavailable there: tests then skip.
#include <cstdint>

namespace rigcal::test {

struct AllocationCounter {
  static bool available();
  static void start();
  static std::uint64_t stop();  // allocations since start()
};

}  // namespace rigcal::test

/// Skips the current test when allocations cannot be counted in this build.
#define RIGCAL_REQUIRE_ALLOCATION_COUNTING()                                                   \
  if (!::rigcal::test::AllocationCounter::available())                                         \
  GTEST_SKIP() << "allocation counting is unavailable under ThreadSanitizer (it owns operator new)"
