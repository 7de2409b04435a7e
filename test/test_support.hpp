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

// The DDS domain of a test: each test that talks DDS passes its own `slot` (0..99), so tests
// running at the same time never see each other's topics.
int test_domain(int slot);

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

 private:
  int pid_ = -1;
  std::optional<int> exit_code_;
  std::filesystem::path output_file_;
};

// Runs a command to completion; returns its exit code and output.
std::pair<int, std::string> run_command(const std::vector<std::string>& argv,
                                        std::map<std::string, std::string> environment = {},
                                        std::chrono::seconds timeout = std::chrono::seconds(60));

// "key: integer" lines, as sequence_sink writes them.
std::map<std::string, long long> read_summary(const std::filesystem::path& path);

}  // namespace mocap::test
