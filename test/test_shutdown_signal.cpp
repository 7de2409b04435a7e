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

#include "shutdown_signal.hpp"
#include "test_support.hpp"

namespace mocap {
namespace {

using namespace std::chrono_literals;

// A child that installs the handlers, registers a forced-exit hook writing `hook_file`, says it
// is ready through a pipe, waits for a stop request and then spends `stopping` on its graceful
// stop (forever when nullopt) before exiting with 0.
pid_t start_child(const std::filesystem::path& hook_file,
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
  return pid;
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
  pid_t child = start_child(dir / "hook", 200ms);
  kill(child, SIGTERM);
  EXPECT_EQ(exit_status(child, 10s), 0);
  EXPECT_FALSE(std::filesystem::exists(dir / "hook"));
}

TEST(ShutdownSignal, TwoSignalsInTheSameInstantAreOneStopRequest) {
  test::TempDir dir;
  pid_t child = start_child(dir / "hook", 300ms);
  kill(child, SIGTERM);
  kill(child, SIGTERM);
  kill(child, SIGINT);
  EXPECT_EQ(exit_status(child, 10s), 0) << "the graceful stop ran to its end";
  EXPECT_FALSE(std::filesystem::exists(dir / "hook"));
}

TEST(ShutdownSignal, ASecondSignalAfterTheDelayForcesTheExitAfterTheHooks) {
  test::TempDir dir;
  pid_t child = start_child(dir / "hook", std::nullopt);  // a graceful stop that hangs
  kill(child, SIGINT);
  kill(child, SIGINT);  // Ctrl-C with a supervisor that forwards it: one request
  EXPECT_EQ(exit_status(child, ShutdownSignal::kEscalationDelay + 500ms), std::nullopt);
  kill(child, SIGINT);  // well after: forced
  EXPECT_EQ(exit_status(child, 10s), 130);
  EXPECT_TRUE(std::filesystem::exists(dir / "hook"));
}

}  // namespace
}  // namespace mocap
