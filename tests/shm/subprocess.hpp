#pragma once
// A child process for the ring tests: fork + immediate exec (what ASan and TSan handle well), stdout and
// stderr piped back, lines read with a timeout, kill and wait with a timeout. The destructor kills
// (SIGKILL) and reaps a child still running, so a failing test never leaves processes behind.
#include <sys/types.h>

#include <chrono>
#include <optional>
#include <string>
#include <vector>

namespace rigcal::shm::test {

class Subprocess {
 public:
  /// Starts argv[0] (a path) with argv, the current environment plus `extra_env` ("NAME=value").
  explicit Subprocess(const std::vector<std::string>& argv, const std::vector<std::string>& extra_env = {});
  ~Subprocess();
  Subprocess(const Subprocess&) = delete;
  Subprocess& operator=(const Subprocess&) = delete;

  [[nodiscard]] pid_t pid() const { return pid_; }
  /// Reads stdout until a line starting with `prefix` arrives; returns it, or nullopt at the timeout or EOF.
  std::optional<std::string> waitForLine(const std::string& prefix, std::chrono::milliseconds timeout);
  /// Sends a signal.
  void kill(int signal);
  /// Waits for the exit (draining the pipes meanwhile): the exit code, 128 + signal if killed, nullopt at
  /// the timeout.
  std::optional<int> wait(std::chrono::milliseconds timeout);

  /// All stdout lines so far, and all stderr text so far.
  [[nodiscard]] const std::vector<std::string>& lines() const { return lines_; }
  [[nodiscard]] const std::string& errText() const { return err_; }
  /// The last stdout line starting with `prefix`, or "".
  [[nodiscard]] std::string lastLine(const std::string& prefix) const;

 private:
  /// Reads what is available within `timeout_ms`; false once both pipes are closed.
  bool pump(int timeout_ms);

  pid_t pid_ = -1;
  int out_fd_ = -1;
  int err_fd_ = -1;
  bool reaped_ = false;
  int status_ = 0;
  std::string out_partial_;
  std::string err_;
  std::vector<std::string> lines_;
  std::size_t consumed_ = 0;  // lines already returned by waitForLine
};

/// Value of `key=` in a "k1=v1 k2=v2" line, or "".
std::string field(const std::string& line, const std::string& key);
/// Integer value of `key=`, or -1.
long long intField(const std::string& line, const std::string& key);

}  // namespace rigcal::shm::test
