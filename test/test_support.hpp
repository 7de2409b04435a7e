// Helpers shared by the tests: paths, temporary folders, child processes, summaries.
#pragma once

#include <chrono>
#include <filesystem>
#include <map>
#include <optional>
#include <string>
#include <string_view>
#include <vector>

namespace mocap::test {

std::filesystem::path bin_dir();          // build/bin
std::filesystem::path test_plugin_dir();  // build/test_plugins
std::filesystem::path plugin_dir();       // build/lib/mocap_graph/plugins: the shipped plugins
std::filesystem::path source_dir();       // the repository

// A fresh directory, removed with everything in it when the object goes.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::filesystem::path& path() const { return path_; }
  std::filesystem::path operator/(std::string_view name) const { return path_ / name; }

 private:
  std::filesystem::path path_;
};

void write_file(const std::filesystem::path& path, std::string_view text);
std::string read_file(const std::filesystem::path& path);

// The DDS implementation the tests run on: MOCAP_DDS_IMPLEMENTATION, else "fastdds".
std::string dds_implementation();

// A TCP port on 127.0.0.1 nobody listens on right now.
int free_port();

// The DDS domain of a test: each test that talks DDS passes its own `slot` (0..99), so tests
// running at the same time never see each other's topics. Domains 100..199 under Fast DDS,
// 0..99 under Cyclone DDS (MOCAP_DDS_IMPLEMENTATION), so the two runs of a test do not meet.
int test_domain(int slot);

// The DDS domain of a test that puts Fast DDS and Cyclone DDS participants side by side (such
// tests run once, not once per implementation): 87 + `index` (0..12), domains no other test
// takes. Their ports (7400 + 250 x domain + offsets) lie below Linux's ephemeral ports (32768
// and up), which other processes' sockets hold for as long as they live: Fast DDS moves on to
// another port, but Cyclone DDS cannot create its participant ("address in use").
int mixed_domain(int index);

// A DDS domain (200..232, beyond every slot's) that no other test process holds while this one
// runs: for the tests of one fixture that may run at the same time, which share a set-up and
// so cannot each name a slot. Held through a lock file in the temporary directory until the
// process ends; the same domain on every call.
int unshared_domain();

// A child process whose stdout and stderr go to a file. Stopped (SIGTERM, then SIGKILL after
// 10 s) if still running when destroyed.
class ChildProcess {
 public:
  ChildProcess(std::vector<std::string> argv, std::map<std::string, std::string> environment,
               std::filesystem::path output_file);
  ~ChildProcess();
  ChildProcess(const ChildProcess&) = delete;
  ChildProcess& operator=(const ChildProcess&) = delete;

  // True once the output holds `text`; false if the process ended or time ran out first.
  bool wait_for_output(std::string_view text, std::chrono::seconds timeout);
  // The exit code (128 + signal for a killed process), or nullopt if still running.
  std::optional<int> wait(std::chrono::seconds timeout);
  void signal(int signal_number);
  std::string output() const;
  int pid() const { return pid_; }

 private:
  int pid_ = -1;
  std::optional<int> exit_code_;
  std::filesystem::path output_file_;
};

// Every core kept busy by other processes (one busy loop per core, at the tests' priority)
// while the object lives: the machine a robot's computer often is.
class BusyCores {
 public:
  BusyCores();
  ~BusyCores();  // kills and reaps them
  BusyCores(const BusyCores&) = delete;
  BusyCores& operator=(const BusyCores&) = delete;
  size_t processes() const { return pids_.size(); }

 private:
  std::vector<int> pids_;
};

// Runs a command to completion; returns its exit code and output.
std::pair<int, std::string> run_command(const std::vector<std::string>& argv,
                                        std::map<std::string, std::string> environment = {},
                                        std::chrono::seconds timeout = std::chrono::seconds(60));

// Two network namespaces ("hosts" A and B, each its own network stack) joined by a veth pair,
// removed when the object goes. Needs root and `ip` (iproute2); error() says what failed.
class TwoHosts {
 public:
  // `multicast` false: no multicast between the hosts (IFF_MULTICAST off, no multicast route,
  // and no group can be joined: igmp_max_memberships 0), as on networks where DDS's multicast
  // discovery cannot work.
  explicit TwoHosts(bool multicast = true);
  ~TwoHosts();
  TwoHosts(const TwoHosts&) = delete;
  TwoHosts& operator=(const TwoHosts&) = delete;

  // Empty when the hosts are up; otherwise why not (no privileges, no `ip`).
  const std::string& error() const { return error_; }
  const std::string& namespace_a() const { return host_a_; }
  const std::string& namespace_b() const { return host_b_; }
  const std::string& address_a() const { return address_a_; }  // IPv4 of A's end of the link
  const std::string& address_b() const { return address_b_; }
  // `command` run inside host A or B (`ip netns exec`).
  std::vector<std::string> on_a(std::vector<std::string> command) const;
  std::vector<std::string> on_b(std::vector<std::string> command) const;
  long long bytes_received_by_a() const;  // over the link; -1 if unknown
  // The link's MTU at both ends (Ethernet's 1500 until set).
  void set_mtu(int mtu) const;

 private:
  std::string host_a_, host_b_, link_a_, link_b_, address_a_, address_b_, error_;
};

// "key: integer" lines, as sequence_sink writes them; throws naming the file when it has none.
std::map<std::string, long long> read_summary(const std::filesystem::path& path);

}  // namespace mocap::test
