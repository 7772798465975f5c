#include "rigcal/shm/ring_segment.hpp"

#include <sys/mman.h>

#include <algorithm>
#include <cstdlib>
#include <stdexcept>

namespace rigcal::shm {

std::string defaultNamePrefix() {
  if (const char* env = std::getenv("RIGCAL_SHM_PREFIX"); env && *env) return env;
  return kDefaultNamePrefix;
}

std::string segmentName(const std::string& sensor, const std::optional<std::string>& prefix) {
  if (sensor.empty()) throw std::invalid_argument("shared-memory ring: empty sensor name");
  const std::string name = prefix.value_or(defaultNamePrefix()) + sensor;
  if (name.find('/') != std::string::npos || name.size() > 200) {
    throw std::invalid_argument("shared-memory ring name '" + name +
                                "' must not contain '/' and must be at most 200 characters");
  }
  return name;
}

std::filesystem::path segmentPath(const std::string& segment) {
  return std::filesystem::path(kShmDir) / segment;
}

std::vector<std::string> listSegments(const std::string& prefix) {
  std::vector<std::string> names;
  std::error_code ec;
  for (const auto& entry : std::filesystem::directory_iterator(kShmDir, ec)) {
    const std::string name = entry.path().filename().string();
    if (name.compare(0, prefix.size(), prefix) == 0 && entry.is_regular_file(ec)) names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  return names;
}

bool removeSegment(const std::string& segment) {
  return ::shm_unlink(("/" + segment).c_str()) == 0;
}

}  // namespace rigcal::shm
