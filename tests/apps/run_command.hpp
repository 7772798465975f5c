#pragma once
// Runs the rigcal executable as a real process and captures what it prints.
#include <memory>
#include <string>
#include <vector>

#include "test_data.hpp"

namespace rigcal::test {

struct CommandResult {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

/// Runs `rigcal args...` (the binary under test) and waits for it.
CommandResult runRigcal(const std::vector<std::string>& args);

/// `rigcal args...` started in the background (stdout/stderr to files in a temp dir).
class RigcalProcess {
 public:
  /// `launcher` (e.g. {"setpriv", "--reuid=65534", ...}) is run with the binary and args appended.
  explicit RigcalProcess(const std::vector<std::string>& args, const std::vector<std::string>& launcher = {});
  ~RigcalProcess();  // kills the process if still running
  RigcalProcess(const RigcalProcess&) = delete;
  RigcalProcess& operator=(const RigcalProcess&) = delete;
  void kill(int signal);
  /// Waits for the exit; returns the exit code (128 + signal when killed) with its output.
  CommandResult wait();
  [[nodiscard]] int pid() const { return pid_; }

 private:
  std::unique_ptr<TempDir> dir_;
  int pid_ = -1;
  bool reaped_ = false;
};

}  // namespace rigcal::test
