// What a ring's driver process counted, as the pipeline reports it (issue 18): from the writer's start when
// we read its first scan, from the first scan we read when we attached to a driver already running (its
// earlier damage is not this run's), and summed over a restarted writer, which counts from zero again.
#include "ring_input_tally.hpp"

#include <gtest/gtest.h>

namespace rigcal::pipeline::detail {
namespace {

shm::DriverTally tally(std::uint64_t packets, std::uint32_t malformed) {
  shm::DriverTally t;
  t.packets = packets;
  t.malformed = malformed;
  t.late_dropped = malformed + 1;
  return t;
}

TEST(RingInputTally, CountsFromTheWritersStartWhenItsFirstScanWasRead) {
  RingInputTally t;
  t.update(tally(100, 2), 0, false);
  t.update(tally(300, 5), 2, false);  // a scan between was overrun: running totals lose nothing
  EXPECT_EQ(t.totals().packets, 300u);
  EXPECT_EQ(t.totals().malformed, 5u);
  EXPECT_EQ(t.totals().late_dropped, 6u);
}

TEST(RingInputTally, CountsFromTheFirstScanReadOfADriverAlreadyRunning) {
  RingInputTally t;
  t.update(tally(10'000, 40), 57, false);
  EXPECT_EQ(t.totals().malformed, 0u);
  t.update(tally(10'300, 43), 58, false);
  EXPECT_EQ(t.totals().packets, 300u);
  EXPECT_EQ(t.totals().malformed, 3u);
}

TEST(RingInputTally, ARestartedWriterAddsToWhatTheFormerOneCounted) {
  RingInputTally t;
  t.update(tally(100, 2), 0, false);
  t.update(tally(200, 4), 1, false);
  t.update(tally(50, 1), 0, true);  // the new writer's first scan: it counts from zero
  EXPECT_EQ(t.totals().packets, 250u);
  EXPECT_EQ(t.totals().malformed, 5u);
}

}  // namespace
}  // namespace rigcal::pipeline::detail
