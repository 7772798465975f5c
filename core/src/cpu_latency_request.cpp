#include "rigcal/core/cpu_latency_request.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cerrno>
#include <cstdint>
#include <cstring>

namespace rigcal {

namespace {
constexpr const char* kPath = "/dev/cpu_dma_latency";
}

CpuLatencyRequest::CpuLatencyRequest(int max_latency_us) {
  fd_ = ::open(kPath, O_WRONLY | O_CLOEXEC);
  if (fd_ < 0) {
    error_ = std::string(kPath) + ": " + std::strerror(errno);
    return;
  }
  // The interface takes a binary 32-bit value in microseconds.
  const std::int32_t value = max_latency_us < 0 ? 0 : max_latency_us;
  if (::write(fd_, &value, sizeof value) != static_cast<ssize_t>(sizeof value)) {
    error_ = std::string(kPath) + ": write: " + std::strerror(errno);
    ::close(fd_);
    fd_ = -1;
  }
}

CpuLatencyRequest::~CpuLatencyRequest() {
  if (fd_ >= 0) ::close(fd_);
}

}  // namespace rigcal
