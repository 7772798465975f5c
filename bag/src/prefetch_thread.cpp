#include "prefetch_thread.hpp"

#include <stdexcept>
#include <utility>

namespace rigcal::bag {

PrefetchThread::PrefetchThread() : thread_([this] { loop(); }) {}

PrefetchThread::~PrefetchThread() {
  {
    std::unique_lock lock(mutex_);
    cv_.wait(lock, [&] { return !busy_; });
    stop_ = true;
  }
  cv_.notify_all();
  thread_.join();
}

void PrefetchThread::submit(std::function<void()> job) {
  {
    std::lock_guard lock(mutex_);
    if (busy_) throw std::logic_error("PrefetchThread::submit while a job runs");
    job_ = std::move(job);
    busy_ = true;
    error_ = nullptr;
  }
  cv_.notify_all();
}

void PrefetchThread::wait() {
  std::exception_ptr error;
  {
    std::unique_lock lock(mutex_);
    cv_.wait(lock, [&] { return !busy_; });
    error = std::exchange(error_, nullptr);
  }
  if (error) std::rethrow_exception(error);
}

void PrefetchThread::loop() {
  std::unique_lock lock(mutex_);
  while (true) {
    cv_.wait(lock, [&] { return stop_ || (busy_ && job_); });
    if (stop_) return;
    std::function<void()> job = std::move(job_);
    job_ = nullptr;
    lock.unlock();
    std::exception_ptr error;
    try {
      job();
    } catch (...) {
      error = std::current_exception();
    }
    lock.lock();
    error_ = error;
    busy_ = false;
    cv_.notify_all();
  }
}

}  // namespace rigcal::bag
