#pragma once
// One worker thread that runs one job at a time for its owner: the MCAP reader reads and inflates the next
// chunk on it while the caller decodes the current one. This moves the work (inflating, the chunk CRC) to
// another core, it does not remove it: it shortens the wall time when a core is free, not the CPU time.
#include <condition_variable>
#include <exception>
#include <functional>
#include <mutex>
#include <thread>

namespace rigcal::bag {

class PrefetchThread {
 public:
  PrefetchThread();
  ~PrefetchThread();  // waits for the job in flight, then stops the thread
  PrefetchThread(const PrefetchThread&) = delete;
  PrefetchThread& operator=(const PrefetchThread&) = delete;

  /// Runs `job` on the worker. One job at a time: wait() for the previous one first.
  void submit(std::function<void()> job);
  /// Until the submitted job has finished; rethrows what it threw. Returns at once if none was submitted.
  void wait();

 private:
  void loop();

  std::mutex mutex_;
  std::condition_variable cv_;
  std::function<void()> job_;
  bool busy_ = false, stop_ = false;
  std::exception_ptr error_;
  std::thread thread_;  // last: started once the members it uses exist
};

}  // namespace rigcal::bag
