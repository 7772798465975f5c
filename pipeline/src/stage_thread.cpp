#include "rigcal/pipeline/stage_thread.hpp"

#include <pthread.h>
#include <sched.h>

#include <atomic>
#include <ctime>
#include <iostream>
#include <memory>
#include <sstream>
#include <stdexcept>

namespace rigcal::pipeline {

namespace {
double threadCpuSeconds(pthread_t thread) {
  clockid_t clock;
  timespec ts{};
  if (pthread_getcpuclockid(thread, &clock) != 0 || clock_gettime(clock, &ts) != 0) return 0.0;
  return double(ts.tv_sec) + double(ts.tv_nsec) * 1e-9;
}
}  // namespace

StageThread::StageThread(std::string name, std::vector<int> cores, std::function<void()> body)
    : name_(std::move(name)), handle_(std::make_shared<std::atomic<pthread_t>>(pthread_t{})) {
  auto final_cpu = final_cpu_seconds_;
  auto handle = handle_;
  const std::string thread_name = name_.substr(0, 15);
  thread_ = std::thread([thread_name, cores = std::move(cores), body = std::move(body), final_cpu, handle] {
    handle->store(pthread_self());
    pthread_setname_np(pthread_self(), thread_name.c_str());
    if (!cores.empty()) {
      cpu_set_t set;
      CPU_ZERO(&set);
      for (int c : cores) CPU_SET(c, &set);
      if (pthread_setaffinity_np(pthread_self(), sizeof set, &set) != 0)
        std::cerr << "warning: could not pin thread " << thread_name << " to the requested cores\n";
    }
    body();
    *final_cpu = threadCpuSeconds(pthread_self());
  });
}

StageThread::~StageThread() { join(); }

void StageThread::join() {
  if (thread_.joinable()) thread_.join();
}

double StageThread::cpuSeconds() const {
  if (!thread_.joinable()) return *final_cpu_seconds_;
  return threadCpuSeconds(handle_->load());
}

std::vector<int> parseCoreList(const std::string& text) {
  std::vector<int> cores;
  std::stringstream in(text);
  std::string part;
  while (std::getline(in, part, ',')) {
    try {
      const auto dash = part.find('-');
      std::size_t used = 0;
      if (dash == std::string::npos) {
        cores.push_back(std::stoi(part, &used));
        if (used != part.size()) throw std::invalid_argument(part);
      } else {
        const int lo = std::stoi(part.substr(0, dash)), hi = std::stoi(part.substr(dash + 1));
        if (lo > hi) throw std::invalid_argument(part);
        for (int c = lo; c <= hi; ++c) cores.push_back(c);
      }
    } catch (const std::exception&) {
      throw std::invalid_argument("'" + text + "' is not a core list (e.g. 0,1 or 0-1)");
    }
  }
  if (cores.empty()) throw std::invalid_argument("'" + text + "' is not a core list (e.g. 0,1 or 0-1)");
  return cores;
}

}  // namespace rigcal::pipeline
