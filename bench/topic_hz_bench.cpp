// Accuracy of `mocap_topic hz`: a publisher paced at 100 Hz to 10 kHz, the tool run against
// it, and its reading compared with the rate the publisher actually kept (from its own clock).
//
//   build/bin/topic_hz_bench
#include <fcntl.h>
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <atomic>
#include <cmath>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <regex>
#include <sstream>
#include <thread>

#include <fmt/format.h>

#include <mocap/component_host.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>

namespace {

using Steady = std::chrono::steady_clock;
using Array = mocap_msgs::msg::FiducialArray;
constexpr const char* kTopic = "/bench/hz";

class HzPublisher final : public mocap::Component {
 public:
  static void declare(mocap::ComponentSpec& spec) {
    spec.publishes<Array>(kTopic, mocap::Qos::reliable(), "");
  }
  explicit HzPublisher(mocap::Context& context) : Component(context) {
    publisher = create_publisher<Array>(kTopic);
  }
  mocap::Publisher<Array> publisher;
};

constexpr mocap::ComponentFactory kFactory = mocap::make_component_factory<HzPublisher>("hz");

// Sleeps until shortly before `deadline`, then spins: sleep alone overshoots by tens of
// microseconds, a tenth of a 10 kHz period.
void wait_until(Steady::time_point deadline) {
  auto spin_from = deadline - std::chrono::microseconds(150);
  if (Steady::now() < spin_from) std::this_thread::sleep_until(spin_from);
  while (Steady::now() < deadline) {
  }
}

struct Measurement {
  double target_hz, kept_hz, reported_hz;
};

Measurement measure(const std::string& tool, double rate_hz, double seconds) {
  mocap::ComponentHost host({.name = "hz_publisher", .threads = 1, .dds = {}});
  auto& publisher = static_cast<HzPublisher&>(host.add(kFactory, {.name = "publisher"}));
  host.start();

  std::string out = fmt::format("/tmp/topic_hz_bench_{}.txt", getpid());
  pid_t child = fork();
  if (child == 0) {
    int fd = open(out.c_str(), O_WRONLY | O_CREAT | O_TRUNC, 0644);
    dup2(fd, STDOUT_FILENO);
    execl(tool.c_str(), tool.c_str(), "hz", kTopic, nullptr);
    _exit(127);
  }
  // Publish until the tool has reported for `seconds`; it averages the last samples.
  auto period =
      std::chrono::duration_cast<Steady::duration>(std::chrono::duration<double>(1.0 / rate_hz));
  auto message = std::make_shared<Array>();
  message->fiducials().resize(12);
  auto start = Steady::now();
  auto next = start;
  std::vector<Steady::time_point> sent;
  sent.reserve(size_t(rate_hz * (seconds + 10)));
  auto end = start + std::chrono::duration_cast<Steady::duration>(
                         std::chrono::duration<double>(seconds + 3));
  while (Steady::now() < end) {
    next += period;
    wait_until(next);
    sent.push_back(Steady::now());
    publisher.publisher.publish(message);
  }
  kill(child, SIGINT);
  waitpid(child, nullptr, 0);
  host.stop();

  std::ifstream in(out);
  std::stringstream text;
  text << in.rdbuf();
  std::remove(out.c_str());
  double reported = NAN;
  static const std::regex line(R"(average rate: ([0-9.]+) Hz)");
  std::string all = text.str();
  for (std::sregex_iterator it(all.begin(), all.end(), line), stop; it != stop; ++it) {
    reported = std::stod((*it)[1]);
  }
  // What the publisher kept over the last third of the run, the span the tool's last report
  // averaged over (its window holds up to 10000 samples).
  size_t window = std::min<size_t>(sent.size() - 1, 10000);
  size_t last = sent.size() - 1;
  double span = std::chrono::duration<double>(sent[last] - sent[last - window]).count();
  return {rate_hz, double(window) / span, reported};
}

}  // namespace

int main() {
  if (getenv("MOCAP_DOMAIN_ID") == nullptr) {
    setenv("MOCAP_DOMAIN_ID", std::to_string(200 + getpid() % 30).c_str(), 1);
  }
  std::string tool =
      (std::filesystem::read_symlink("/proc/self/exe").parent_path() / "mocap_topic").string();
  fmt::print("topic_hz_bench: mocap_topic hz against a paced publisher (target 1 % or better)\n\n");
  fmt::print("| {:>10} | {:>16} | {:>16} | {:>8} |\n", "target Hz", "publisher kept Hz",
             "mocap_topic hz", "error");
  fmt::print("|{:-<12}|{:-<18}|{:-<18}|{:-<10}|\n", "", "", "", "");
  for (double rate : {100.0, 1000.0, 5000.0, 10000.0}) {
    Measurement m = measure(tool, rate, rate >= 1000 ? 4.0 : 6.0);
    fmt::print("| {:>10.0f} | {:>16.2f} | {:>16.2f} | {:>7.3f}% |\n", m.target_hz, m.kept_hz,
               m.reported_hz, 100.0 * (m.reported_hz - m.kept_hz) / m.kept_hz);
  }
  return 0;
}
