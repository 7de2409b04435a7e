// Stop requests as supervisors send them, to a child process that runs ShutdownSignal: one
// signal, two in the same instant (`timeout`, process-group kills, `docker stop`), and a second
// one after the escalation delay while the graceful stop hangs.
#include <gtest/gtest.h>

#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <optional>
#include <thread>

#include "core/shutdown_signal.hpp"
#include "test/test_support.hpp"

namespace mocap {
namespace {

using namespace std::chrono_literals;

// The child, killed and reaped at the end of the test if it has not exited: a failed test must
// not leave behind a process that holds ctest's output pipe open (ctest waits for it to close).
class Child {
 public:
  explicit Child(pid_t pid) : pid_(pid) {}
  Child(const Child&) = delete;
  Child& operator=(const Child&) = delete;
  ~Child() {
    if (waitpid(pid_, nullptr, WNOHANG) == 0) {
      kill(pid_, SIGKILL);
      waitpid(pid_, nullptr, 0);
    }
  }
  pid_t pid() const { return pid_; }

 private:
  pid_t pid_;
};

// A child that installs the handlers, registers a forced-exit hook writing `hook_file`, says it
// is ready through a pipe, waits for a stop request and then spends `stopping` on its graceful
// stop (forever when nullopt) before exiting with 0.
Child start_child(const std::filesystem::path& hook_file,
                  std::optional<std::chrono::milliseconds> stopping) {
  int ready[2];
  EXPECT_EQ(pipe(ready), 0);
  pid_t pid = fork();
  if (pid == 0) {
    close(ready[0]);
    ShutdownSignal::install();
    ForcedExitHook hook([&] { std::ofstream(hook_file) << "written\n"; });
    char byte = 'r';
    if (write(ready[1], &byte, 1) != 1) _exit(3);
    if (!ShutdownSignal::wait(std::nullopt)) _exit(4);
    if (!stopping) {
      for (;;) pause();
    }
    std::this_thread::sleep_for(*stopping);
    _exit(0);
  }
  close(ready[1]);
  char byte = 0;
  EXPECT_EQ(read(ready[0], &byte, 1), 1);
  close(ready[0]);
  return Child(pid);
}

// The child's exit status, 128 + N for signal N, or nullopt if it runs past `timeout`.
std::optional<int> exit_status(pid_t pid, std::chrono::milliseconds timeout) {
  const auto end = std::chrono::steady_clock::now() + timeout;
  for (;;) {
    int status = 0;
    if (waitpid(pid, &status, WNOHANG) == pid) {
      return WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
    }
    if (std::chrono::steady_clock::now() > end) return std::nullopt;
    std::this_thread::sleep_for(10ms);
  }
}

TEST(ShutdownSignal, OneSignalStopsGracefully) {
  test::TempDir dir;
  Child child = start_child(dir / "hook", 200ms);
  kill(child.pid(), SIGTERM);
  EXPECT_EQ(exit_status(child.pid(), 10s), 0);
  EXPECT_FALSE(std::filesystem::exists(dir / "hook"));
}

TEST(ShutdownSignal, TwoSignalsInTheSameInstantAreOneStopRequest) {
  test::TempDir dir;
  Child child = start_child(dir / "hook", 300ms);
  kill(child.pid(), SIGTERM);
  kill(child.pid(), SIGTERM);
  kill(child.pid(), SIGINT);
  EXPECT_EQ(exit_status(child.pid(), 10s), 0) << "the graceful stop ran to its end";
  EXPECT_FALSE(std::filesystem::exists(dir / "hook"));
}

TEST(ShutdownSignal, ASecondSignalAfterTheDelayForcesTheExitAfterTheHooks) {
  test::TempDir dir;
  Child child = start_child(dir / "hook", std::nullopt);  // a graceful stop that hangs
  kill(child.pid(), SIGINT);
  kill(child.pid(), SIGINT);  // Ctrl-C with a supervisor that forwards it: one request
  EXPECT_EQ(exit_status(child.pid(), ShutdownSignal::kEscalationDelay + 500ms), std::nullopt);
  kill(child.pid(), SIGINT);  // well after: forced
  EXPECT_EQ(exit_status(child.pid(), 10s), 130);
  EXPECT_TRUE(std::filesystem::exists(dir / "hook"));
}

}  // namespace
}  // namespace mocap
