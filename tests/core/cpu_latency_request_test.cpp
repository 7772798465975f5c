#include "rigcal/core/cpu_latency_request.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cstdint>
#include <optional>

#include <gtest/gtest.h>

namespace rigcal {
namespace {

// One test, not several: ctest runs tests in parallel and they would see each other's requests.
// The kernel's current aggregate limit in µs; nullopt where the device cannot be read.
std::optional<std::int32_t> currentLimit() {
  const int fd = ::open("/dev/cpu_dma_latency", O_RDONLY | O_CLOEXEC);
  if (fd < 0) return std::nullopt;
  std::int32_t v = 0;
  const bool ok = ::read(fd, &v, sizeof v) == static_cast<ssize_t>(sizeof v);
  ::close(fd);
  return ok ? std::optional(v) : std::nullopt;
}

TEST(CpuLatencyRequest, HoldsTheLimitWhileAliveAndReleasesIt) {
  const auto before = currentLimit();
  {
    CpuLatencyRequest request(0);
    if (!request.active()) {
      // Without the device or the right to write it the request says why, on one line.
      EXPECT_NE(request.error().find("/dev/cpu_dma_latency"), std::string::npos) << request.error();
      GTEST_SKIP() << "cannot hold a CPU latency request here: " << request.error();
    }
    EXPECT_TRUE(request.error().empty());
    ASSERT_TRUE(currentLimit().has_value());
    EXPECT_EQ(*currentLimit(), 0);
    {
      CpuLatencyRequest negative(-5);  // clamped to 0, and a second holder keeps the limit
      EXPECT_TRUE(negative.active());
    }
    EXPECT_EQ(*currentLimit(), 0);  // the first request still holds it
  }
  EXPECT_EQ(currentLimit(), before);
}

}  // namespace
}  // namespace rigcal
