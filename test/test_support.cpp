#include "test/test_support.hpp"

#include <arpa/inet.h>
#include <fcntl.h>
#include <netinet/in.h>
#include <signal.h>
#include <sys/file.h>
#include <sys/socket.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <thread>

#include "host/dds_implementations.hpp"

namespace mocap::test {
namespace fs = std::filesystem;

fs::path bin_dir() { return MOCAP_TEST_BIN_DIR; }
fs::path test_plugin_dir() { return MOCAP_TEST_PLUGIN_DIR; }
fs::path plugin_dir() { return bin_dir().parent_path() / "lib" / "mocap_graph" / "plugins"; }
fs::path source_dir() { return MOCAP_TEST_SOURCE_DIR; }

TempDir::TempDir() {
  std::random_device random;
  path_ = fs::temp_directory_path() /
          ("mocap_test_" + std::to_string(getpid()) + "_" + std::to_string(random()));
  fs::create_directories(path_);
}

TempDir::~TempDir() {
  std::error_code ignored;
  fs::remove_all(path_, ignored);
}

void write_file(const fs::path& path, std::string_view text) {
  std::ofstream out(path);
  out << text;
}

std::string read_file(const fs::path& path) {
  std::ifstream in(path);
  std::stringstream text;
  text << in.rdbuf();
  return text.str();
}

std::string dds_implementation() {
  const char* implementation = std::getenv("MOCAP_DDS_IMPLEMENTATION");
  return implementation != nullptr && *implementation != '\0'
             ? implementation
             : std::string(dds_implementations().front().name);
}

int free_port() {
  const int fd = socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof(address));
  socklen_t size = sizeof(address);
  getsockname(fd, reinterpret_cast<sockaddr*>(&address), &size);
  close(fd);
  return ntohs(address.sin_port);
}

int test_domain(int slot) {
  return (dds_implementation() == dds_implementations().front().name ? 100 : 0) + slot;
}

int mixed_domain(int index) {
  if (index < 0 || index > 12) throw std::invalid_argument("mixed_domain takes 0..12");
  return 87 + index;
}

int unshared_domain() {
  // 232: the highest domain whose ports (7400 + 250 x domain + offsets) fit in 16 bits.
  static const int domain = [] {
    for (int candidate = 200; candidate <= 232; ++candidate) {
      const fs::path lock =
          fs::temp_directory_path() / ("mocap_test_domain_" + std::to_string(candidate) + ".lock");
      const int fd = open(lock.c_str(), O_RDWR | O_CREAT | O_CLOEXEC, 0666);
      if (fd < 0) throw std::runtime_error("cannot open " + lock.string());
      if (flock(fd, LOCK_EX | LOCK_NB) == 0) return candidate;  // fd stays open: the lock held
      close(fd);
    }
    throw std::runtime_error("every DDS domain of 200..232 is held by another test process");
  }();
  return domain;
}

ChildProcess::ChildProcess(std::vector<std::string> argv,
                           std::map<std::string, std::string> environment, fs::path output_file)
    : output_file_(std::move(output_file)) {
  int fd = open(output_file_.c_str(), O_WRONLY | O_CREAT | O_TRUNC | O_CLOEXEC, 0644);
  if (fd < 0) throw std::runtime_error("cannot create " + output_file_.string());
  pid_ = fork();
  if (pid_ == 0) {
    dup2(fd, STDOUT_FILENO);
    dup2(fd, STDERR_FILENO);
    for (const auto& [name, value] : environment) setenv(name.c_str(), value.c_str(), 1);
    std::vector<char*> args;
    for (std::string& arg : argv) args.push_back(arg.data());
    args.push_back(nullptr);
    execvp(args[0], args.data());
    _exit(127);
  }
  close(fd);
}

ChildProcess::~ChildProcess() {
  // SIGTERM first: a process killed outright leaves its DDS shared memory behind.
  if (!exit_code_) {
    kill(pid_, SIGTERM);
    wait(std::chrono::seconds(10));
  }
  if (!exit_code_) {
    kill(pid_, SIGKILL);
    wait(std::chrono::seconds(10));
  }
}

std::string ChildProcess::output() const { return read_file(output_file_); }

bool ChildProcess::wait_for_output(std::string_view text, std::chrono::seconds timeout) {
  auto deadline = std::chrono::steady_clock::now() + timeout;
  while (std::chrono::steady_clock::now() < deadline) {
    if (output().find(text) != std::string::npos) return true;
    if (wait(std::chrono::seconds(0))) return output().find(text) != std::string::npos;
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
  return false;
}

std::optional<int> ChildProcess::wait(std::chrono::seconds timeout) {
  auto deadline = std::chrono::steady_clock::now() + timeout;
  while (!exit_code_) {
    int status = 0;
    if (waitpid(pid_, &status, WNOHANG) == pid_) {
      exit_code_ = WIFEXITED(status) ? WEXITSTATUS(status) : 128 + WTERMSIG(status);
      break;
    }
    if (std::chrono::steady_clock::now() >= deadline) break;
    std::this_thread::sleep_for(std::chrono::milliseconds(20));
  }
  return exit_code_;
}

void ChildProcess::signal(int signal_number) {
  if (!exit_code_) kill(pid_, signal_number);
}

BusyCores::BusyCores() {
  unsigned cores = std::max(1u, std::thread::hardware_concurrency());
  for (unsigned i = 0; i < cores; ++i) {
    int pid = fork();
    if (pid == 0) {
      // Only async-signal-safe work after fork() in a threaded process: a bare loop.
      volatile uint64_t spin = 0;
      for (;;) spin = spin + 1;
    }
    if (pid > 0) pids_.push_back(pid);
  }
}

BusyCores::~BusyCores() {
  for (int pid : pids_) kill(pid, SIGKILL);
  for (int pid : pids_) waitpid(pid, nullptr, 0);
}

std::pair<int, std::string> run_command(const std::vector<std::string>& argv,
                                        std::map<std::string, std::string> environment,
                                        std::chrono::seconds timeout) {
  TempDir dir;
  ChildProcess child(argv, std::move(environment), dir / "output");
  std::optional<int> code = child.wait(timeout);
  if (!code) return {-1, child.output() + "\n(timed out)"};  // the destructor stops it
  return {*code, child.output()};
}

TwoHosts::TwoHosts(bool multicast) {
  // Unique per process and object, so tests may run at once; short enough for a link name.
  static std::atomic<int> counter{0};
  int serial = counter.fetch_add(1) % 100;
  std::string id = std::to_string(getpid() % 100000) + "x" + std::to_string(serial);
  host_a_ = "mocap_a_" + id;
  host_b_ = "mocap_b_" + id;
  std::string link_a = "mva" + id, link_b = "mvb" + id;
  link_a_ = link_a;
  link_b_ = link_b;
  std::string subnet = "10.77." + std::to_string((getpid() + serial) % 250);
  address_a_ = subnet + ".1";
  address_b_ = subnet + ".2";
  // Left behind by a killed run of a process with the same id: would make `add` fail.
  run_command({"ip", "netns", "del", host_a_});
  run_command({"ip", "netns", "del", host_b_});
  std::vector<std::vector<std::string>> commands = {
      {"ip", "netns", "add", host_a_},
      {"ip", "netns", "add", host_b_},
      {"ip", "link", "add", link_a, "type", "veth", "peer", "name", link_b},
      {"ip", "link", "set", link_a, "netns", host_a_},
      {"ip", "link", "set", link_b, "netns", host_b_},
      {"ip", "-n", host_a_, "addr", "add", address_a_ + "/24", "dev", link_a},
      {"ip", "-n", host_b_, "addr", "add", address_b_ + "/24", "dev", link_b},
      {"ip", "-n", host_a_, "link", "set", "lo", "up"},
      {"ip", "-n", host_b_, "link", "set", "lo", "up"},
      {"ip", "-n", host_a_, "link", "set", link_a, "multicast", multicast ? "on" : "off"},
      {"ip", "-n", host_b_, "link", "set", link_b, "multicast", multicast ? "on" : "off"},
      {"ip", "-n", host_a_, "link", "set", link_a, "up"},
      {"ip", "-n", host_b_, "link", "set", link_b, "up"}};
  if (!multicast) {
    // IFF_MULTICAST alone stops nothing: a sender naming the interface still sends, and veth
    // delivers. A host that may join no multicast group receives none.
    for (const std::string& host : {host_a_, host_b_}) {
      commands.push_back({"ip", "netns", "exec", host, "sh", "-c",
                          "echo 0 > /proc/sys/net/ipv4/igmp_max_memberships"});
    }
  } else {  // DDS discovery is multicast.
    commands.push_back({"ip", "-n", host_a_, "route", "add", "224.0.0.0/4", "dev", link_a});
    commands.push_back({"ip", "-n", host_b_, "route", "add", "224.0.0.0/4", "dev", link_b});
  }
  for (const auto& command : commands) {
    auto [code, output] = run_command(command);
    if (code != 0) {
      error_.clear();
      for (const std::string& word : command) error_ += word + " ";
      error_ += ": " + output;
      return;
    }
  }
}

TwoHosts::~TwoHosts() {
  run_command({"ip", "netns", "del", host_a_});
  run_command({"ip", "netns", "del", host_b_});
  if (!error_.empty()) run_command({"ip", "link", "del", link_a_});  // if never moved
}

std::vector<std::string> TwoHosts::on_a(std::vector<std::string> command) const {
  command.insert(command.begin(), {"ip", "netns", "exec", host_a_});
  return command;
}

std::vector<std::string> TwoHosts::on_b(std::vector<std::string> command) const {
  command.insert(command.begin(), {"ip", "netns", "exec", host_b_});
  return command;
}

long long TwoHosts::bytes_received_by_a() const {
  auto [code, output] =
      run_command(on_a({"cat", "/sys/class/net/" + link_a_ + "/statistics/rx_bytes"}));
  return code == 0 ? std::stoll(output) : -1;
}

void TwoHosts::set_mtu(int mtu) const {
  run_command({"ip", "-n", host_a_, "link", "set", link_a_, "mtu", std::to_string(mtu)});
  run_command({"ip", "-n", host_b_, "link", "set", link_b_, "mtu", std::to_string(mtu)});
}

std::map<std::string, long long> read_summary(const fs::path& path) {
  std::map<std::string, long long> summary;
  std::ifstream in(path);
  std::string line;
  while (std::getline(in, line)) {
    size_t colon = line.find(':');
    if (colon == std::string::npos) continue;
    summary[line.substr(0, colon)] = std::stoll(line.substr(colon + 1));
  }
  // A missing summary would otherwise surface as a bare `map::at` in the caller.
  if (summary.empty()) throw std::runtime_error(path.string() + ": no summary written");
  return summary;
}

}  // namespace mocap::test
