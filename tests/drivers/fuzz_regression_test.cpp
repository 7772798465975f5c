// Inputs the fuzzers (fuzz/) found, kept as regression tests (they need the ASan+UBSan build to bite).
#include <gtest/gtest.h>

#include <vector>

#include "rigcal/drivers/ipv4_reassembler.hpp"

namespace rigcal::drivers {
namespace {

// fuzz_link_layer: a fragment with no payload made the reassembler memcpy from a null pointer (UB).
TEST(FuzzRegression, EmptyIpv4FragmentIsHarmless) {
  Ipv4Reassembler reassembler(4);
  Ipv4Header empty;
  empty.identification = 7;
  empty.more_fragments = true;
  empty.fragment_offset = 0;
  empty.protocol = 17;
  EXPECT_TRUE(reassembler.add(empty).empty());
  empty.more_fragments = false;
  EXPECT_TRUE(reassembler.add(empty).empty()) << "a zero-length datagram is never complete";
  // The same datagram id still reassembles once real fragments arrive.
  std::vector<std::uint8_t> first(16, 1), last(4, 2);
  Ipv4Header a = empty, b = empty;
  a.more_fragments = true;
  a.payload = first;
  b.fragment_offset = 16;
  b.payload = last;
  EXPECT_TRUE(reassembler.add(a).empty());
  EXPECT_EQ(reassembler.add(b).size(), 20u);
}

}  // namespace
}  // namespace rigcal::drivers
