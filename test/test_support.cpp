#include "test_support.hpp"

#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <fstream>
#include <random>
#include <sstream>
#include <stdexcept>
#include <thread>

namespace mocap::test {
namespace fs = std::filesystem;

fs::path bin_dir() { return MOCAP_TEST_BIN_DIR; }
fs::path test_plugin_dir() { return MOCAP_TEST_PLUGIN_DIR; }
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

int test_domain(int slot) { return 100 + slot; }

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

std::pair<int, std::string> run_command(const std::vector<std::string>& argv,
                                        std::map<std::string, std::string> environment,
                                        std::chrono::seconds timeout) {
  TempDir dir;
  ChildProcess child(argv, std::move(environment), dir / "output");
  std::optional<int> code = child.wait(timeout);
  if (!code) return {-1, child.output() + "\n(timed out)"};  // the destructor stops it
  return {*code, child.output()};
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
  return summary;
}

}  // namespace mocap::test
