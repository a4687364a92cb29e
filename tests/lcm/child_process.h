// A child process for the end-to-end tests: started with posix_spawn, waited for with a
// deadline, killed when the test ends early.
#pragma once

#include <fcntl.h>
#include <signal.h>
#include <spawn.h>
#include <sys/wait.h>

#include <chrono>
#include <string>
#include <thread>
#include <vector>

extern char** environ;

namespace panmap {
namespace test {

class ChildProcess {
 public:
  /// Starts `args[0]` (searched in PATH) with stdout and stderr going to `log_path`.
  explicit ChildProcess(std::vector<std::string> args, const std::string& log_path = "/dev/null") {
    std::vector<char*> argv;
    for (std::string& a : args) argv.push_back(a.data());
    argv.push_back(nullptr);
    posix_spawn_file_actions_t actions;
    posix_spawn_file_actions_init(&actions);
    posix_spawn_file_actions_addopen(&actions, 1, log_path.c_str(), O_WRONLY | O_CREAT | O_TRUNC,
                                     0644);
    posix_spawn_file_actions_adddup2(&actions, 1, 2);
    started_ = posix_spawnp(&pid_, argv[0], &actions, nullptr, argv.data(), environ) == 0;
    posix_spawn_file_actions_destroy(&actions);
  }
  ~ChildProcess() {
    if (running()) {
      ::kill(pid_, SIGKILL);
      ::waitpid(pid_, nullptr, 0);
    }
  }
  bool started() const { return started_; }
  bool running() const { return started_ && !exited_; }
  /// Waits up to `timeout_s` for the exit; true when it exited (exit code in exitCode()).
  bool wait(double timeout_s) {
    const auto deadline = std::chrono::steady_clock::now() +
                          std::chrono::milliseconds(static_cast<int64_t>(timeout_s * 1000));
    while (running()) {
      int status = 0;
      if (::waitpid(pid_, &status, WNOHANG) == pid_) {
        exited_ = true;
        exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : -1;
        break;
      }
      if (std::chrono::steady_clock::now() > deadline) return false;
      std::this_thread::sleep_for(std::chrono::milliseconds(20));  // polling, not a timing assert
    }
    return exited_;
  }
  /// Sends a signal.
  void signal(int sig) {
    if (running()) ::kill(pid_, sig);
  }
  int exitCode() const { return exit_code_; }

 private:
  pid_t pid_ = 0;
  bool started_ = false;
  bool exited_ = false;
  int exit_code_ = -1;
};

}  // namespace test
}  // namespace panmap
