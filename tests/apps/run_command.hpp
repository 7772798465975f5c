#pragma once
// Runs the rigcal executable as a real process and captures what it prints.
#include <string>
#include <vector>

namespace rigcal::test {

struct CommandResult {
  int exit_code = -1;
  std::string out;  // stdout
  std::string err;  // stderr
};

/// Runs `rigcal args...` (the binary under test) and waits for it.
CommandResult runRigcal(const std::vector<std::string>& args);

}  // namespace rigcal::test
