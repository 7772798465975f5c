#include "rigcal/shm/liveness.hpp"

#include <fcntl.h>
#include <unistd.h>

#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <ctime>
#include <string>

namespace rigcal::shm {

namespace {

std::int64_t clockNs(clockid_t clock) {
  timespec ts{};
  ::clock_gettime(clock, &ts);
  return std::int64_t{ts.tv_sec} * 1'000'000'000 + ts.tv_nsec;
}

}  // namespace

const char* toString(WriterStatus status) {
  switch (status) {
    case WriterStatus::kAbsent: return "absent";
    case WriterStatus::kAlive: return "alive";
    case WriterStatus::kStalled: return "stalled";
    case WriterStatus::kDead: return "dead";
    case WriterStatus::kClosed: return "closed";
  }
  return "?";
}

std::optional<std::uint64_t> processStartTime(std::int32_t pid) {
  if (pid <= 0) return std::nullopt;
  // read(2) on a stack buffer rather than an ifstream: called from reader wait loops, it must not allocate.
  char path[32];
  std::snprintf(path, sizeof path, "/proc/%d/stat", static_cast<int>(pid));
  const int fd = ::open(path, O_RDONLY | O_CLOEXEC);
  if (fd < 0) return std::nullopt;
  char buf[1024];
  const ssize_t n = ::read(fd, buf, sizeof buf - 1);
  ::close(fd);
  if (n <= 0) return std::nullopt;
  buf[n] = '\0';
  // "pid (comm) state ppid ..." — comm may hold spaces and parentheses, so parse from the last ')'.
  const char* p = std::strrchr(buf, ')');
  if (!p || p[1] != ' ') return std::nullopt;
  p += 2;
  const char state = *p;
  if (state == 'Z' || state == 'X' || state == 'x') return std::nullopt;  // killed, waiting to be reaped
  // After ')' come fields 3 (state) .. ; starttime is field 22, i.e. the 20th after the state.
  for (int field = 3; field < 22; ++field) {
    p = std::strchr(p, ' ');
    if (!p) return std::nullopt;
    ++p;
  }
  char* end = nullptr;
  const unsigned long long start = std::strtoull(p, &end, 10);
  if (end == p) return std::nullopt;
  return start;
}

ProcessIdentity selfIdentity() {
  ProcessIdentity me;
  me.pid = static_cast<std::int32_t>(::getpid());
  me.start_time = processStartTime(me.pid).value_or(0);
  return me;
}

bool processAlive(const ProcessIdentity& who) {
  const auto start = processStartTime(who.pid);
  return start && *start == who.start_time;
}

std::int64_t monotonicNs() { return clockNs(CLOCK_MONOTONIC); }
std::int64_t realtimeNs() { return clockNs(CLOCK_REALTIME); }

WriterStatus evaluateWriter(const RingHeader& header, std::chrono::nanoseconds stall_after) {
  const auto state = static_cast<WriterState>(header.writer_state.load(std::memory_order_acquire));
  switch (state) {
    case WriterState::kNone: return WriterStatus::kAbsent;
    case WriterState::kClosed: return WriterStatus::kClosed;
    case WriterState::kClaiming: return WriterStatus::kAlive;
    case WriterState::kRunning: break;
    default: return WriterStatus::kDead;
  }
  const ProcessIdentity writer{header.writer_pid.load(std::memory_order_acquire),
                               header.writer_start_time.load(std::memory_order_acquire)};
  if (!processAlive(writer)) return WriterStatus::kDead;
  const std::int64_t age = monotonicNs() - header.heartbeat_ns.load(std::memory_order_relaxed);
  return age > stall_after.count() ? WriterStatus::kStalled : WriterStatus::kAlive;
}

}  // namespace rigcal::shm
