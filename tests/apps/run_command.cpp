#include "run_command.hpp"

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>
#include <unistd.h>

#include <stdexcept>

#include "test_data.hpp"

extern char** environ;

namespace rigcal::test {

RigcalProcess::RigcalProcess(const std::vector<std::string>& args, const std::vector<std::string>& launcher)
    : dir_(std::make_unique<TempDir>()) {
  std::vector<std::string> argv_storage = launcher;
  argv_storage.push_back(rigcalBinary().string());
  const std::string bin = argv_storage.front();
  argv_storage.insert(argv_storage.end(), args.begin(), args.end());
  std::vector<char*> argv;
  for (auto& a : argv_storage) argv.push_back(a.data());
  argv.push_back(nullptr);
  posix_spawn_file_actions_t actions;
  posix_spawn_file_actions_init(&actions);
  posix_spawn_file_actions_addopen(&actions, 1, (*dir_ / "out").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  posix_spawn_file_actions_addopen(&actions, 2, (*dir_ / "err").c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
  pid_t pid = 0;
  const int rc = posix_spawnp(&pid, bin.c_str(), &actions, nullptr, argv.data(), environ);
  posix_spawn_file_actions_destroy(&actions);
  if (rc != 0) throw std::runtime_error("cannot start " + bin);
  pid_ = pid;
}

RigcalProcess::~RigcalProcess() {
  if (!reaped_ && pid_ > 0) {
    ::kill(pid_, SIGKILL);
    waitpid(pid_, nullptr, 0);
  }
}

void RigcalProcess::kill(int signal) { ::kill(pid_, signal); }

CommandResult RigcalProcess::wait() {
  int status = 0;
  waitpid(pid_, &status, 0);
  reaped_ = true;
  CommandResult result;
  result.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
  result.out = fileContents(*dir_ / "out");
  result.err = fileContents(*dir_ / "err");
  return result;
}

CommandResult runRigcal(const std::vector<std::string>& args) { return RigcalProcess(args).wait(); }

}  // namespace rigcal::test
