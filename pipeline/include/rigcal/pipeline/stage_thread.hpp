#pragma once
// A pipeline stage's thread: named (visible in top/perf), optionally pinned to a set of cores, and
// able to report the CPU time it used.
#include <atomic>
#include <functional>
#include <memory>
#include <string>
#include <thread>
#include <vector>

namespace rigcal::pipeline {

class StageThread {
 public:
  StageThread() = default;
  /// Starts `body` on a new thread called `name` (15 chars max, as Linux allows), pinned to `cores`
  /// when non-empty. A failed pin is reported once on stderr and ignored.
  StageThread(std::string name, std::vector<int> cores, std::function<void()> body);
  StageThread(StageThread&&) noexcept = default;
  StageThread& operator=(StageThread&&) noexcept = default;
  ~StageThread();

  void join();
  /// CPU seconds used by the thread so far (or in total, after join()).
  [[nodiscard]] double cpuSeconds() const;
  [[nodiscard]] const std::string& name() const { return name_; }

 private:
  std::string name_;
  std::thread thread_;
  std::shared_ptr<double> final_cpu_seconds_ = std::make_shared<double>(0.0);
  std::shared_ptr<std::atomic<pthread_t>> handle_;
};

/// Parses "0,1" or "0-1" into core ids; throws std::invalid_argument naming the text.
std::vector<int> parseCoreList(const std::string& text);

}  // namespace rigcal::pipeline
