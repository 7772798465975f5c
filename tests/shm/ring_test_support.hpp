#pragma once
#include "allocation_counter.hpp"
// What the ring tests share: a segment-name prefix no other test (or test run) uses, removed with every
// segment under it when the test ends; the peer executable; the allocation counter.
#include <atomic>
#include <cstdint>
#include <string>
#include <vector>

namespace rigcal::shm::test {

/// "rigcal-test-<pid>-<n>." — unique per test; the destructor removes any segment left under it.
class UniquePrefix {
 public:
  UniquePrefix();
  ~UniquePrefix();
  UniquePrefix(const UniquePrefix&) = delete;
  UniquePrefix& operator=(const UniquePrefix&) = delete;
  [[nodiscard]] const std::string& str() const { return prefix_; }
  /// Segments currently under the prefix.
  [[nodiscard]] std::vector<std::string> segments() const;

 private:
  std::string prefix_;
};

/// The ring_peer executable built next to the tests.
std::string peerPath();

using rigcal::test::AllocationCounter;  // tests/support/allocation_counter.hpp

}  // namespace rigcal::shm::test
