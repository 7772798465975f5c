#pragma once
// Test helpers: where the real sensor captures are, and scratch directories.
#include <filesystem>
#include <string>

namespace rigcal::test {

/// ../shared/data, or $RIGCAL_DATA_DIR when set.
std::filesystem::path dataDir();

/// True when running under CI (CI=true): missing shared data is then a failure, not a skip.
bool inCi();

/// A fresh, empty directory under the system temp dir, removed by the destructor.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  [[nodiscard]] const std::filesystem::path& path() const { return path_; }
  [[nodiscard]] std::filesystem::path operator/(const std::string& name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

/// The rigcal executable under test ($RIGCAL_BIN, set by ctest).
std::filesystem::path rigcalBinary();

/// A file's bytes; empty when it cannot be read (a test then fails on what it expected to find).
std::string fileContents(const std::filesystem::path& file);

}  // namespace rigcal::test

/// Resolves `relative` under dataDir() into `var`; skips the test (fails under CI) when it is absent.
#define RIGCAL_REQUIRE_DATA(var, relative)                                                   \
  const std::filesystem::path var = ::rigcal::test::dataDir() / (relative);                  \
  if (!std::filesystem::exists(var)) {                                                       \
    if (::rigcal::test::inCi()) FAIL() << "shared test data missing under CI: " << var;      \
    GTEST_SKIP() << "shared test data not found: " << var << " (set RIGCAL_DATA_DIR)";       \
  }
