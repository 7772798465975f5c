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

}  // namespace rigcal::shm::test
