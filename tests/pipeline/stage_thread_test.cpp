#include <gtest/gtest.h>

#include <sched.h>

#include <chrono>
#include <ctime>

#include "rigcal/pipeline/stage_thread.hpp"

namespace rigcal::pipeline {
namespace {

TEST(StageThread, RunsPinnedAndReportsCpuTime) {
  int cpu_seen = -1;
  volatile double sink = 0;
  StageThread t("test-stage", {0}, [&] {
    // Burn 30 ms of this thread's own CPU time, however busy the machine is.
    timespec ts{};
    do {
      for (int i = 0; i < 1000; ++i) sink = sink + 1.0;
      clock_gettime(CLOCK_THREAD_CPUTIME_ID, &ts);
    } while (double(ts.tv_sec) + double(ts.tv_nsec) * 1e-9 < 0.03);
    cpu_seen = sched_getcpu();
  });
  t.join();
  EXPECT_EQ(cpu_seen, 0);
  EXPECT_GE(t.cpuSeconds(), 0.03);
  EXPECT_LT(t.cpuSeconds(), 1.0);
}

TEST(StageThread, BlockedThreadUsesNoCpu) {
  StageThread t("sleeper", {}, [] { std::this_thread::sleep_for(std::chrono::milliseconds(100)); });
  t.join();
  EXPECT_LT(t.cpuSeconds(), 0.01);
}

TEST(StageThread, ParsesCoreLists) {
  EXPECT_EQ(parseCoreList("0,1"), (std::vector<int>{0, 1}));
  EXPECT_EQ(parseCoreList("0-2"), (std::vector<int>{0, 1, 2}));
  EXPECT_THROW(parseCoreList("zero"), std::invalid_argument);
  EXPECT_THROW(parseCoreList("2-1"), std::invalid_argument);
  EXPECT_THROW(parseCoreList(""), std::invalid_argument);
}

}  // namespace
}  // namespace rigcal::pipeline
