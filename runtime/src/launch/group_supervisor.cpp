#include "launch/group_supervisor.hpp"

#include <fcntl.h>
#include <poll.h>
#include <signal.h>
#include <sys/prctl.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <cstdlib>
#include <cstring>
#include <string_view>

#include <fmt/format.h>

#include <mocap/launch_start.hpp>

#include "core/shutdown_signal.hpp"

extern char** environ;

namespace mocap {
namespace {

constexpr auto kStopGrace = std::chrono::seconds(10);
// Groups stop themselves at the deployment's end; this long after it, they are stopped.
constexpr auto kDurationGrace = std::chrono::seconds(15);
constexpr const char* kReadyFdVariable = "MOCAP_READY_FD";
// The child's end of its ready pipe.
constexpr int kReadyFd = 3;

using Time = std::chrono::steady_clock::time_point;
Time now() { return std::chrono::steady_clock::now(); }
double seconds(std::chrono::steady_clock::duration d) {
  return std::chrono::duration<double>(d).count();
}

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
  // Starting: not yet told us it runs. Waiting: dead, to be started again at `restart_at`.
  // Ended: for good (finished, failed, given up, stopped).
  enum class State { Starting, Running, Waiting, Ended };

  const ChildProcess* spec;
  RestartPolicy restarts;
  State state = State::Ended;
  pid_t pid = -1;
  Stream out, err;
  int ready_fd = -1;  // read end of its ready pipe, while Starting
  int starts = 0;
  std::string last_end;  // how its last process ended, told to the next (its diagnostics)
  Time started_at{}, restart_at{};
  bool alive() const { return state == State::Starting || state == State::Running; }
};

void close_fd(int& fd) {
  if (fd >= 0) ::close(fd);
  fd = -1;
}

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
    if (n == 0 && stream.fd >= 0) close_fd(stream.fd);  // end of file
    break;                                              // EAGAIN or closed
  }
  if ((flush_partial || stream.fd < 0) && !stream.partial.empty()) {
    write_all(stream.target, fmt::format("[{}] {}\n", child.spec->name, stream.partial));
    stream.partial.clear();
  }
}

// Starts the child's program with `extra` arguments; false (errno set) when it cannot.
bool start(Child& child, const std::vector<std::string>& extra) {
  int out[2], err[2], ready[2];
  if (pipe2(out, O_CLOEXEC) != 0) return false;
  if (pipe2(err, O_CLOEXEC) != 0) {
    close(out[0]);
    close(out[1]);
    return false;
  }
  if (pipe2(ready, O_CLOEXEC) != 0) {
    for (int fd : {out[0], out[1], err[0], err[1]}) close(fd);
    return false;
  }
  // Everything the child needs is made before fork(): between fork() and exec() only
  // async-signal-safe calls are allowed, since other threads may hold the allocator's locks.
  std::vector<std::string> args = child.spec->argv;
  args.insert(args.end(), extra.begin(), extra.end());
  std::vector<char*> argv;
  for (std::string& arg : args) argv.push_back(arg.data());
  argv.push_back(nullptr);
  // The variables this supervisor sets replace inherited ones of the same name.
  std::vector<std::string> own_variables = {fmt::format("{}={}", kReadyFdVariable, kReadyFd)};
  if (child.starts > 0) {
    own_variables.push_back(fmt::format("{}={}", kGroupRestartsVariable, child.starts));
    own_variables.push_back(fmt::format("{}={}", kGroupLastEndVariable, child.last_end));
  }
  auto own = [&](std::string_view variable) {
    return std::any_of(own_variables.begin(), own_variables.end(), [&](const std::string& set) {
      return variable.starts_with(std::string_view(set.data(), set.find('=') + 1));
    });
  };
  std::vector<char*> envp;
  for (char** variable = environ; *variable; ++variable) {
    if (!own(*variable)) envp.push_back(*variable);
  }
  for (std::string& variable : own_variables) envp.push_back(variable.data());
  envp.push_back(nullptr);
  std::string exec_failed = fmt::format("cannot run {}\n", args.front());
  pid_t parent = getpid();
  pid_t pid = fork();
  if (pid < 0) {
    for (int fd : {out[0], out[1], err[0], err[1], ready[0], ready[1]}) close(fd);
    return false;
  }
  if (pid == 0) {
    // Own process group: a terminal's Ctrl-C reaches only the supervisor, which then stops
    // each child exactly once. Die with the supervisor if it is killed.
    setpgid(0, 0);
    prctl(PR_SET_PDEATHSIG, SIGTERM);
    if (getppid() != parent) _exit(127);
    dup2(out[1], STDOUT_FILENO);
    dup2(err[1], STDERR_FILENO);
    if (ready[1] == kReadyFd) {
      fcntl(kReadyFd, F_SETFD, 0);  // dup2 onto itself would keep close-on-exec
    } else {
      dup2(ready[1], kReadyFd);
    }
    execve(argv[0], argv.data(), envp.data());
    [[maybe_unused]] ssize_t ignored =
        ::write(STDERR_FILENO, exec_failed.data(), exec_failed.size());
    _exit(127);
  }
  close(out[1]);
  close(err[1]);
  close(ready[1]);
  fcntl(out[0], F_SETFL, O_NONBLOCK);
  fcntl(err[0], F_SETFL, O_NONBLOCK);
  fcntl(ready[0], F_SETFL, O_NONBLOCK);
  child.pid = pid;
  child.state = Child::State::Starting;
  child.out = {out[0], STDOUT_FILENO, {}};
  child.err = {err[0], STDERR_FILENO, {}};
  child.ready_fd = ready[0];
  child.started_at = now();
  ++child.starts;
  return true;
}

// How a child ended, for messages: "exited with code 3", "was killed by signal 9".
std::string how_it_ended(int status) {
  return WIFSIGNALED(status) ? fmt::format("was killed by signal {}", WTERMSIG(status))
                             : fmt::format("exited with code {}", WEXITSTATUS(status));
}

// The supervision of one set of children: their output, their ends and restarts, the stop
// and its escalation.
class Supervisor {
 public:
  Supervisor(const std::vector<ChildProcess>& specs, const SupervisionOptions& options)
      : options_(options), children_(specs.size()) {
    if (options_.duration) end_ = now() + *options_.duration;
    for (size_t i = 0; i < specs.size(); ++i) {
      children_[i].spec = &specs[i];
      children_[i].restarts = RestartPolicy(options_.restarts);
      if (!start_child(children_[i])) {
        say(fmt::format("cannot start group '{}': {}", specs[i].name, std::strerror(errno)));
        result_ = 1;
        stop_all("");
        break;
      }
    }
  }
  ~Supervisor() {
    for (Child& child : children_) {
      close_fd(child.out.fd);
      close_fd(child.err.fd);
      close_fd(child.ready_fd);
    }
  }

  // Until every child has ended; the exit code.
  int run() {
    const Time deadline = end_ ? *end_ + kDurationGrace : Time::max();
    for (;;) {
      forward_output();
      take_ready_notices();
      reap();
      restart_due();
      if (std::none_of(children_.begin(), children_.end(), [](const Child& child) {
            return child.alive() || child.state == Child::State::Waiting;
          })) {
        return result_;
      }
      if (ShutdownSignal::received()) stop_all("stopping all groups");
      if (now() >= deadline) stop_all("time is up; stopping all groups");
      if (now() >= kill_deadline_) escalate();
    }
  }

 private:
  bool start_child(Child& child) {
    std::vector<std::string> extra;
    if (end_) {
      extra = {"--duration", fmt::format("{:.3f}", std::max(0.001, seconds(*end_ - now())))};
    }
    if (!start(child, extra)) return false;
    say(fmt::format("group '{}' started (pid {})", child.spec->name, child.pid));
    return true;
  }

  void event(int level, std::string text) {
    say(text);
    if (options_.on_event) options_.on_event({level, std::move(text)});
  }

  void stop_all(std::string_view why) {
    if (stopping_) return;
    stopping_ = true;
    if (!why.empty()) say(why);
    for (Child& child : children_) {
      if (child.alive()) kill(child.pid, SIGTERM);
      if (child.state == Child::State::Waiting) child.state = Child::State::Ended;
    }
    kill_deadline_ = now() + kStopGrace;
  }

  // Waits up to 100 ms (less when a restart is due) for output or a ready notice, and passes
  // on the output there is.
  void forward_output() {
    std::vector<pollfd> fds;
    Time wake = now() + std::chrono::milliseconds(100);
    for (Child& child : children_) {
      for (int fd : {child.out.fd, child.err.fd, child.ready_fd}) {
        if (fd >= 0) fds.push_back({fd, POLLIN, 0});
      }
      if (child.state == Child::State::Waiting) wake = std::min(wake, child.restart_at);
    }
    const auto wait_ms = std::chrono::ceil<std::chrono::milliseconds>(wake - now()).count();
    poll(fds.data(), fds.size(), static_cast<int>(std::max<int64_t>(0, wait_ms)));
    for (Child& child : children_) {
      forward(child, child.out, false);
      forward(child, child.err, false);
    }
  }

  void take_ready_notices() {
    for (Child& child : children_) {
      if (child.ready_fd < 0) continue;
      char byte;
      const ssize_t n = ::read(child.ready_fd, &byte, 1);
      if (n < 0 && (errno == EAGAIN || errno == EWOULDBLOCK)) continue;
      close_fd(child.ready_fd);  // told, or its end closed without telling
      if (n == 1 && child.state == Child::State::Starting) {
        child.state = Child::State::Running;
        if (child.starts > 1) {
          say(fmt::format("group '{}' is running again, {:.2f} s after its start", child.spec->name,
                          seconds(now() - child.started_at)));
        }
      }
    }
  }

  // Children that have ended: their last output, then what their end means.
  void reap() {
    for (Child& child : children_) {
      if (!child.alive()) continue;
      int status = 0;
      if (waitpid(child.pid, &status, WNOHANG) != child.pid) continue;
      take_ready_notices();  // a notice sent just before it died counts
      const bool had_started = child.state == Child::State::Running;
      child.state = Child::State::Ended;
      close_fd(child.ready_fd);
      forward(child, child.out, true);
      forward(child, child.err, true);
      const int code = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      if (stopping_) {
        // A group stopped on request by a signal of ours has not failed.
        const bool stopped_by_us = WIFSIGNALED(status) && WTERMSIG(status) == SIGTERM;
        if (code != 0 && !stopped_by_us) fail(code);
        continue;
      }
      ended(child, status, code, had_started);
    }
  }

  void ended(Child& child, int status, int code, bool had_started) {
    const std::string& name = child.spec->name;
    child.last_end = how_it_ended(status);
    if (code == 0) {
      stop_all(fmt::format("group '{}' finished; stopping the others", name));
      return;
    }
    if (!had_started && child.starts == 1) {
      fail(code);
      stop_all(fmt::format("group '{}' {} while starting; stopping the others", name,
                           how_it_ended(status)));
      return;
    }
    const std::string died = fmt::format("group '{}' {} {:.1f} s after its start", name,
                                         how_it_ended(status), seconds(now() - child.started_at));
    if (child.spec->required) {
      fail(code);
      event(2, died + "; it is required: stopping the others");
      stop_all("");
      return;
    }
    if (!child.spec->respawn) {
      fail(code);
      event(2, died + "; not restarted (respawn: false), the others go on");
      return;
    }
    const std::optional<RestartPolicy::Duration> delay = child.restarts.on_death(now());
    const RestartPolicyOptions& policy = child.restarts.options();
    if (!delay) {
      fail(code);
      event(2, fmt::format("{}; it died {} times within {} s: given up, the others go on", died,
                           policy.max_deaths, policy.window.count()));
      return;
    }
    if (end_ && now() + *delay >= *end_) {
      event(1, died + "; not restarted: the deployment ends first");
      return;
    }
    child.state = Child::State::Waiting;
    child.restart_at = now() + *delay;
    event(1, fmt::format("{}; restarting it in {:.2f} s (death {} of {} within {} s before it is "
                         "given up)",
                         died, seconds(*delay), child.restarts.deaths_within_window(now()),
                         policy.max_deaths, policy.window.count()));
  }

  void restart_due() {
    for (Child& child : children_) {
      if (child.state != Child::State::Waiting || now() < child.restart_at) continue;
      if (!start_child(child)) {
        fail(1);
        child.state = Child::State::Ended;
        event(2, fmt::format("cannot start group '{}' again: {}", child.spec->name,
                             std::strerror(errno)));
      }
    }
  }

  // The exit code: the first failure's.
  void fail(int code) {
    if (result_ == 0) result_ = code;
  }

  // A group still running kStopGrace after the request gets a second one, which forces its
  // exit after its ForcedExitHooks (a recorder's metadata); one that has not exited when those
  // had their time is killed.
  void escalate() {
    for (Child& child : children_) {
      if (!child.alive()) continue;
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

  const SupervisionOptions& options_;
  std::vector<Child> children_;
  std::optional<Time> end_;  // of the deployment's duration
  int result_ = 0;
  bool stopping_ = false, forcing_ = false;
  Time kill_deadline_ = Time::max();
};

}  // namespace

int supervise(const std::vector<ChildProcess>& specs, const SupervisionOptions& options) {
  ShutdownSignal::install();
  return Supervisor(specs, options).run();
}

SupervisorReadyNotice::SupervisorReadyNotice() {
  const char* text = std::getenv(kReadyFdVariable);
  if (text == nullptr) return;
  const int fd = std::atoi(text);
  unsetenv(kReadyFdVariable);
  // Only a pipe's write end is ours to write to.
  if (fd > STDERR_FILENO && fcntl(fd, F_GETFL) != -1) {
    fcntl(fd, F_SETFD, FD_CLOEXEC);
    fd_ = fd;
  }
}

SupervisorReadyNotice::~SupervisorReadyNotice() {
  if (fd_ >= 0) ::close(fd_);
}

void SupervisorReadyNotice::started() {
  if (fd_ < 0) return;
  write_all(fd_, "1");
  ::close(fd_);
  fd_ = -1;
}

}  // namespace mocap
