// The SIGBUS guard of the ring readers (shm/src/sigbus_guard.hpp): a mapping truncated by another process
// while it is being read costs a false return, not the process; outside the guard nothing changes.
#include "sigbus_guard.hpp"

#include <gtest/gtest.h>
#include <fcntl.h>
#include <sys/mman.h>
#include <unistd.h>

#include <chrono>
#include <cstddef>
#include <cstdio>
#include <cstdlib>
#include <filesystem>
#include <fstream>
#include <string>

#include "subprocess.hpp"
#include "test_data.hpp"

namespace rigcal::shm {
namespace {

using namespace std::chrono_literals;

TEST(SigbusGuard, AMappingTruncatedByAnotherProcessIsAFalseReturn) {
  rigcal::test::TempDir dir;
  const std::filesystem::path file = dir / "mapping";
  const long page = ::sysconf(_SC_PAGESIZE);
  { std::ofstream(file) << std::string(std::size_t(4 * page), 'x'); }
  const int fd = ::open(file.c_str(), O_RDONLY);
  ASSERT_GE(fd, 0);
  auto* base = static_cast<const volatile std::byte*>(::mmap(nullptr, std::size_t(4 * page), PROT_READ, MAP_SHARED, fd, 0));
  ::close(fd);
  ASSERT_NE(static_cast<const void*>(const_cast<const std::byte*>(base)), MAP_FAILED);

  unsigned sum = 0;
  auto touch_last_page = [&] { sum += unsigned(base[3 * page]); };
  ASSERT_TRUE(detail::runCatchingSigbus(touch_last_page)) << "an intact mapping reads";
  EXPECT_EQ(sum, unsigned('x'));

  // Another process cuts the file to one page: the last page of our mapping has no backing any more.
  test::Subprocess truncate({"/usr/bin/truncate", "-s", std::to_string(page), file.string()});
  ASSERT_EQ(truncate.wait(10s), 0) << truncate.errText();
  EXPECT_FALSE(detail::runCatchingSigbus(touch_last_page)) << "the SIGBUS became a false return";
  EXPECT_FALSE(detail::runCatchingSigbus(touch_last_page)) << "and again: the signal is not left blocked";
  auto touch_first_page = [&] { sum += unsigned(base[0]); };
  EXPECT_TRUE(detail::runCatchingSigbus(touch_first_page)) << "the page still backed reads";
  ::munmap(const_cast<std::byte*>(base), std::size_t(4 * page));
}

TEST(SigbusGuardDeathTest, ASigbusOutsideTheGuardStillKills) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  rigcal::test::TempDir dir;
  const std::filesystem::path file = dir / "mapping";
  const long page = ::sysconf(_SC_PAGESIZE);
  { std::ofstream(file) << std::string(std::size_t(2 * page), 'x'); }
  EXPECT_DEATH(
      {
        auto nothing = [] {};
        (void)detail::runCatchingSigbus(nothing);  // the handler is installed
        const int fd = ::open(file.c_str(), O_RDWR);
        auto* base = static_cast<volatile std::byte*>(
            ::mmap(nullptr, std::size_t(2 * page), PROT_READ, MAP_SHARED, fd, 0));
        if (::ftruncate(fd, 0) != 0) std::abort();
        std::fprintf(stderr, "touching\n");
        (void)base[page];
      },
      "touching");
}

}  // namespace
}  // namespace rigcal::shm
