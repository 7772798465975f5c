#pragma once
// Holds the kernel's CPU wake-up latency limit (PM QoS, /dev/cpu_dma_latency) at a bound while alive.
// Why: a reader blocked on a futex is woken on another core by an inter-processor interrupt; if that core
// sat in a deep idle state (on a VM: halted in the hypervisor) the wake-up alone costs 40–100 µs. With the
// limit at 0 an idle core polls instead, which costs power, never CPU time of runnable threads. This is what
// latency tools (cyclictest) do; a latency-critical deployment opts in (`--low-latency`).
#include <string>

namespace rigcal {

class CpuLatencyRequest {
 public:
  /// Requests `max_latency_us` (0 = no idle state deeper than polling). Never throws: check active().
  explicit CpuLatencyRequest(int max_latency_us = 0);
  ~CpuLatencyRequest();
  CpuLatencyRequest(const CpuLatencyRequest&) = delete;
  CpuLatencyRequest& operator=(const CpuLatencyRequest&) = delete;

  /// True while the limit is held (the kernel keeps it as long as the file stays open).
  [[nodiscard]] bool active() const { return fd_ >= 0; }
  /// Why it is not active ("/dev/cpu_dma_latency: Permission denied"), empty when active.
  [[nodiscard]] const std::string& error() const { return error_; }

 private:
  int fd_ = -1;
  std::string error_;
};

}  // namespace rigcal
