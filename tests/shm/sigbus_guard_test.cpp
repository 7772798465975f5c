// The truncation shield of the ring readers (shm/src/sigbus_guard.hpp): a mapping whose file another process
// truncates reads zeros instead of killing the reader with SIGBUS; outside a shielded mapping nothing changes.
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

TEST(TruncationShield, AMappingTruncatedByAnotherProcessReadsZerosInsteadOfASigbus) {
  rigcal::test::TempDir dir;
  const std::filesystem::path file = dir / "mapping";
  const long page = ::sysconf(_SC_PAGESIZE);
  const auto bytes = std::size_t(4 * page);
  { std::ofstream(file) << std::string(bytes, 'x'); }
  const int fd = ::open(file.c_str(), O_RDWR);
  ASSERT_GE(fd, 0);
  void* mapping = ::mmap(nullptr, bytes, PROT_READ | PROT_WRITE, MAP_SHARED, fd, 0);
  ::close(fd);
  ASSERT_NE(mapping, MAP_FAILED);
  auto* base = static_cast<volatile unsigned char*>(mapping);
  {
    detail::TruncationShield shield(mapping, bytes);
    ASSERT_TRUE(shield.active());
    EXPECT_EQ(base[3 * page], 'x');
    EXPECT_FALSE(shield.tripped());
    // Another process cuts the file to one page: the last pages of our mapping lose their backing.
    test::Subprocess truncate({"/usr/bin/truncate", "-s", std::to_string(page), file.string()});
    ASSERT_EQ(truncate.wait(10s), 0) << truncate.errText();
    EXPECT_EQ(base[3 * page], 0) << "zero pages, not a SIGBUS";
    EXPECT_TRUE(shield.tripped());
    base[2 * page] = 7;  // writable, as the reader's own record in the header must be
    EXPECT_EQ(base[2 * page], 7);
  }
  ::munmap(mapping, bytes);
}

TEST(TruncationShieldDeathTest, ASigbusOutsideEveryShieldStillKills) {
  GTEST_FLAG_SET(death_test_style, "threadsafe");
  const long page = ::sysconf(_SC_PAGESIZE);
  EXPECT_DEATH(
      {
        int other = 0;
        detail::TruncationShield elsewhere(&other, sizeof other);  // the handler is installed
        // An unnamed file: the child dies here, so nothing it named would be removed (a TempDir was left in /tmp).
        std::FILE* file = std::tmpfile();
        if (file == nullptr) std::abort();
        const int fd = ::fileno(file);
        if (::ftruncate(fd, 2 * page) != 0) std::abort();
        auto* base = static_cast<volatile unsigned char*>(
            ::mmap(nullptr, std::size_t(2 * page), PROT_READ, MAP_SHARED, fd, 0));
        if (::ftruncate(fd, 0) != 0) std::abort();
        std::fprintf(stderr, "touching\n");
        (void)base[page];
      },
      "touching");
}

}  // namespace
}  // namespace rigcal::shm
