#include "launch/group_supervisor.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstring>

#include <fmt/format.h>

#include "core/shutdown_signal.hpp"

namespace mocap {
namespace {

constexpr auto kStopGrace = std::chrono::seconds(10);

void write_all(int fd, std::string_view text) {
  while (!text.empty()) {
    ssize_t n = ::write(fd, text.data(), text.size());
    if (n <= 0) return;
    text.remove_prefix(static_cast<size_t>(n));
  }
}

void say(std::string_view message) {
  write_all(STDERR_FILENO, fmt::format("[launch] {}\n", message));
}

struct Stream {
  int fd = -1;      // read end of the child's pipe
  int target = -1;  // our stdout or stderr
  std::string partial;
};

struct Child {
  const ChildProcess* spec;
  pid_t pid = -1;
  Stream out, err;
  bool running = false;
  int exit_code = 0;
};

void forward(Child& child, Stream& stream, bool flush_partial) {
  char buffer[4096];
  for (;;) {
    ssize_t n = stream.fd < 0 ? 0 : ::read(stream.fd, buffer, sizeof buffer);
    if (n > 0) {
      stream.partial.append(buffer, static_cast<size_t>(n));
      size_t newline;
      while ((newline = stream.partial.find('\n')) != std::string::npos) {
        write_all(stream.target,
                  fmt::format("[{}] {}\n", child.spec->name, stream.partial.substr(0, newline)));
        stream.partial.erase(0, newline + 1);
      }
      continue;
    }
    if (n == 0 && stream.fd >= 0) {  // end of file
      ::close(stream.fd);
      stream.fd = -1;
    }
    break;  // EAGAIN or closed
  }
  if ((flush_partial || stream.fd < 0) && !stream.partial.empty()) {
    write_all(stream.target, fmt::format("[{}] {}\n", child.spec->name, stream.partial));
    stream.partial.clear();
  }
}

bool start(Child& child) {
  int out[2], err[2];
  if (pipe2(out, O_CLOEXEC) != 0) return false;
  if (pipe2(err, O_CLOEXEC) != 0) {
    close(out[0]);
    close(out[1]);
    return false;
  }
  // Everything the child needs is made before fork(): between fork() and exec() only
  // async-signal-safe calls are allowed, since other threads may hold the allocator's locks.
  std::vector<char*> argv;
  for (const std::string& arg : child.spec->argv) argv.push_back(const_cast<char*>(arg.c_str()));
  argv.push_back(nullptr);
  std::string exec_failed = fmt::format("cannot run {}\n", child.spec->argv.front());
  pid_t parent = getpid();
  pid_t pid = fork();
  if (pid < 0) return false;
  if (pid == 0) {
    // Own process group: a terminal's Ctrl-C reaches only the supervisor, which then stops
    // each child exactly once. Die with the supervisor if it is killed.
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(127);
    dup2(out[1], STDOUT_FILENO);
    dup2(err[1], STDERR_FILENO);
    execv(argv[0], argv.data());
    [[maybe_unused]] ssize_t ignored =
        ::write(STDERR_FILENO, exec_failed.data(), exec_failed.size());
    _exit(127);
  }
  close(out[1]);
  close(err[1]);
  fcntl(out[0], F_SETFL, O_NONBLOCK);
  fcntl(err[0], F_SETFL, O_NONBLOCK);
  child.pid = pid;
  child.running = true;
  child.out = {out[0], STDOUT_FILENO, {}};
  child.err = {err[0], STDERR_FILENO, {}};
  return true;
}

// The supervision of one set of children: their output, their ends, the stop and its
// escalation.
class Supervisor {
 public:
  explicit Supervisor(const std::vector<ChildProcess>& specs) : children_(specs.size()) {
    for (size_t i = 0; i < specs.size(); ++i) {
      children_[i].spec = &specs[i];
      if (!start(children_[i])) {
        say(fmt::format("cannot start group '{}': {}", specs[i].name, std::strerror(errno)));
        result_ = 1;
        stop_all("");
        break;
      }
    }
  }
  ~Supervisor() {
    for (Child& child : children_) {
      for (Stream* s : {&child.out, &child.err}) {
        if (s->fd >= 0) close(s->fd);
      }
    }
  }

  // Until every child has ended; the exit code (0, or the first failing child's).
  int run(std::optional<std::chrono::steady_clock::duration> timeout) {
    const auto deadline = timeout ? now() + *timeout : Time::max();
    for (;;) {
      forward_output();
      reap();
      if (std::none_of(children_.begin(), children_.end(),
                       [](const Child& child) { return child.running; })) {
        return result_;
      }
      if (ShutdownSignal::received()) stop_all("stopping all groups");
      if (now() >= deadline) stop_all("time is up; stopping all groups");
      if (now() >= kill_deadline_) escalate();
    }
  }

 private:
  using Time = std::chrono::steady_clock::time_point;
  static Time now() { return std::chrono::steady_clock::now(); }

  void stop_all(std::string_view why) {
    if (stopping_) return;
    stopping_ = true;
    if (!why.empty()) say(why);
    for (Child& child : children_) {
      if (child.running) kill(child.pid, SIGTERM);
    }
    kill_deadline_ = now() + kStopGrace;
  }

  // Waits up to 100 ms for output, and passes on what there is.
  void forward_output() {
    std::vector<pollfd> fds;
    for (Child& child : children_) {
      for (Stream* s : {&child.out, &child.err}) {
        if (s->fd >= 0) fds.push_back({s->fd, POLLIN, 0});
      }
    }
    poll(fds.data(), fds.size(), 100);
    for (Child& child : children_) {
      forward(child, child.out, false);
      forward(child, child.err, false);
    }
  }

  // Children that have ended: their last output, their exit code; the first to end stops the
  // others.
  void reap() {
    for (Child& child : children_) {
      if (!child.running) continue;
      int status = 0;
      if (waitpid(child.pid, &status, WNOHANG) != child.pid) continue;
      child.running = false;
      child.exit_code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      forward(child, child.out, true);
      forward(child, child.err, true);
      // A group stopped on request by a signal of ours has not failed.
      bool stopped_by_us = stopping_ && WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM;
      if (child.exit_code != 0 && !stopped_by_us && result_ == 0) result_ = child.exit_code;
      if (!stopping_) {
        stop_all(child.exit_code == 0
                     ? fmt::format("group '{}' finished; stopping the others", child.spec->name)
                 : WIFSIGNALED(status)
                     ? fmt::format("group '{}' was killed by signal {}; stopping the others",
                                   child.spec->name, WTERMSIG(status))
                     : fmt::format("group '{}' exited with code {}; stopping the others",
                                   child.spec->name, child.exit_code));
      }
    }
  }

  // A group still running kStopGrace after the request gets a second one, which forces its
  // exit after its ForcedExitHooks (a recorder's metadata); one that has not exited when those
  // had their time is killed.
  void escalate() {
    for (Child& child : children_) {
      if (!child.running) continue;
      if (!forcing_) {
        say(fmt::format("group '{}' did not stop within {} s; forcing its exit", child.spec->name,
                        kStopGrace.count()));
        kill(child.pid, SIGTERM);
      } else {
        say(fmt::format("group '{}' did not exit when forced; killing it", child.spec->name));
        kill(child.pid, SIGKILL);
      }
    }
    kill_deadline_ = forcing_
                         ? Time::max()
                         : now() + std::chrono::seconds(ShutdownSignal::kForcedExitSeconds + 1);
    forcing_ = true;
  }

  std::vector<Child> children_;
  int result_ = 0;
  bool stopping_ = false, forcing_ = false;
  Time kill_deadline_ = Time::max();
};

}  // namespace

int supervise(const std::vector<ChildProcess>& specs,
              std::optional<std::chrono::steady_clock::duration> timeout) {
  ShutdownSignal::install();
  return Supervisor(specs).run(timeout);
}

}  // namespace mocap
