#include "test_data.hpp"

#include <unistd.h>

#include <atomic>
#include <cstdlib>
#include <fstream>
#include <iterator>
#include <stdexcept>

namespace rigcal::test {

std::filesystem::path dataDir() {
  if (const char* env = std::getenv("RIGCAL_DATA_DIR"); env && *env) return env;
  return RIGCAL_DEFAULT_DATA_DIR;
}

bool inCi() {
  const char* ci = std::getenv("CI");
  return ci && std::string(ci) == "true";
}

TempDir::TempDir() {
  static std::atomic<int> counter{0};
  path_ = std::filesystem::temp_directory_path() /
          ("rigcal-test-" + std::to_string(::getpid()) + "-" + std::to_string(counter++));
  std::filesystem::remove_all(path_);
  std::filesystem::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ec;
  std::filesystem::remove_all(path_, ec);
}

std::filesystem::path rigcalBinary() {
  const char* bin = std::getenv("RIGCAL_BIN");
  if (!bin || !*bin) throw std::runtime_error("RIGCAL_BIN is not set (run the tests through ctest)");
  return bin;
}

std::string fileContents(const std::filesystem::path& file) {
  std::ifstream in(file, std::ios::binary);
  return {std::istreambuf_iterator<char>(in), {}};
}

}  // namespace rigcal::test
