// What DDS Security costs one hop between two processes through the runtime: the same hop
// with and without it (authentication, access control, and AES-GCM encryption of discovery,
// liveliness and every message, as scripts/make_security.sh's governance asks), over shared
// memory and over UDP, all measured in this run.
//
//   build/bin/security_bench [--quick]
//
// Credentials are made for the run with scripts/make_security.sh (openssl). One-way latency:
// the publisher stamps each message with CLOCK_MONOTONIC just before publishing, the
// subscriber process subtracts it from its own reading on arrival. Throughput: reliable QoS,
// publishing as fast as flow control allows, from the first publication to the last arrival.
#include <signal.h>
#include <sys/wait.h>
#include <unistd.h>

#include <algorithm>
#include <condition_variable>
#include <cstdio>
#include <filesystem>
#include <fstream>
#include <mutex>
#include <thread>

#include <fmt/format.h>

#include <mocap/component_host.hpp>
#include <mocap_msgs/msg/fiducial_array.hpp>
#include <sensor_msgs/msg/image.hpp>

#include "bench/one_hop.hpp"

namespace {

namespace fs = std::filesystem;
using namespace mocap::one_hop;

// `security`: the credentials folder, or empty for none.
mocap::DdsOptions dds_options(const std::string& security, bool shared_memory,
                              const std::string& identity) {
  mocap::DdsOptions options;
  options.shared_memory = shared_memory;
  if (!security.empty()) {
    options.security_directory = security;
    options.security_identity = identity;
  }
  return options;
}

// The subscriber process: `security` is "-" for none.
template <class T>
int run_subscriber(const std::string& security, bool shared_memory, int total,
                   const std::string& out) {
  mocap::ComponentHost host(
      {.name = "bench_subscriber",
       .threads = 2,
       .dds = dds_options(security == "-" ? "" : security, shared_memory, "subscriber")});
  host.add(kSubscriberFactory<T>, {.name = "subscriber"});
  host.start();
  received.wait_for(total, std::chrono::seconds(120));
  host.stop();
  std::lock_guard lock(received.mutex);
  std::ofstream file(out);
  file << received.count << " " << received.first_ns << " " << received.last_ns << "\n";
  for (double l : received.latencies_us) file << l << "\n";
  return 0;
}

struct Result {
  std::vector<double> latencies_us;  // pooled over rounds
  std::vector<double> msgs_per_s;    // one per round
  double bytes = 0;
  int delivered = 0, expected = 0;
};

struct Path {
  std::string label;
  bool secure;
  bool shared_memory;
};

// One measurement: a subscriber process, this process publishing.
template <class T>
void run_hop(const std::string& self, const std::string& security, const Path& path,
             const Size& size, bool throughput, Result& result) {
  int count = throughput ? size.throughput_count : size.latency_count;
  std::string out = fmt::format("/tmp/security_bench_{}.txt", getpid());
  std::remove(out.c_str());
  pid_t child = fork();
  if (child == 0) {
    execl(self.c_str(), self.c_str(), "--subscriber", path.secure ? security.c_str() : "-",
          path.shared_memory ? "shm" : "udp", size.image ? "image" : "fiducials",
          std::to_string(kWarmup + count).c_str(), out.c_str(), nullptr);
    _exit(127);
  }
  T message = prototype<T>(size);
  int64_t first = 0;
  {
    mocap::ComponentHost host(
        {.name = "bench_publisher",
         .threads = 2,
         .dds = dds_options(path.secure ? security : "", path.shared_memory, "publisher")});
    auto& publisher =
        static_cast<BenchPublisher<T>&>(host.add(kPublisherFactory<T>, {.name = "pub"}));
    host.start();
    for (int i = 0; i < 2000 && publisher.publisher.matched_subscribers() == 0; ++i) {
      std::this_thread::sleep_for(std::chrono::milliseconds(10));
    }
    std::this_thread::sleep_for(std::chrono::milliseconds(300));  // let discovery settle
    auto shared = std::make_shared<T>(message);
    first = publish_all(count, throughput ? 0 : size.latency_rate_hz, [&] {
      stamp(*shared);
      publisher.publisher.publish(shared);
      return stamp_ns(*shared);
    });
    waitpid(child, nullptr, 0);
  }
  std::ifstream in(out);
  int delivered = 0;
  int64_t first_ns = 0, last_ns = 0;
  in >> delivered >> first_ns >> last_ns;
  std::vector<double> latencies;
  for (double l; in >> l;) latencies.push_back(l);
  std::remove(out.c_str());
  result.delivered += delivered;
  result.expected += kWarmup + count;
  result.bytes = double(mocap::message_type<T>().serialized_size(&message));
  if (throughput) {
    if (last_ns > first) result.msgs_per_s.push_back(delivered / (double(last_ns - first) / 1e9));
  } else {
    result.latencies_us.insert(result.latencies_us.end(), latencies.begin(), latencies.end());
  }
}

double median(std::vector<double> values) { return quantile(std::move(values), 0.5); }

void print_row(const std::string& size, const std::string& path, const Result& latency,
               const Result& throughput) {
  std::string notes;
  int delivered = latency.delivered + throughput.delivered;
  int expected = latency.expected + throughput.expected;
  if (delivered != expected) notes = fmt::format("  (delivered {} of {})", delivered, expected);
  double rate = median(throughput.msgs_per_s);
  fmt::print("| {:<28} | {:<21} | {:>9.1f} | {:>9.1f} | {:>8.0f} | {:>8.1f} |{}\n", size, path,
             quantile(latency.latencies_us, 0.5), quantile(latency.latencies_us, 0.99), rate,
             rate * throughput.bytes / 1e6, notes);
}

template <class T>
void measure(const std::string& self, const std::string& security, const Size& size, int rounds) {
  const std::vector<Path> paths = {{"plain, shared memory", false, true},
                                   {"secure, shared memory", true, true},
                                   {"plain, UDP", false, false},
                                   {"secure, UDP", true, false}};
  std::vector<Result> latency(paths.size()), throughput(paths.size());
  Size part = size;
  part.latency_count = std::max(1, size.latency_count / rounds);
  part.throughput_count = std::max(1, size.throughput_count / rounds);
  for (int round = 0; round < rounds; ++round) {
    // Alternate the order, so that drift in the machine's load favours neither.
    for (size_t k = 0; k < paths.size(); ++k) {
      size_t i = round % 2 == 0 ? k : k ^ 1;
      run_hop<T>(self, security, paths[i], part, false, latency[i]);
      run_hop<T>(self, security, paths[i], part, true, throughput[i]);
    }
  }
  std::string label = fmt::format("{} @{} Hz", size.label, size.latency_rate_hz);
  for (size_t i = 0; i < paths.size(); ++i) {
    print_row(i == 0 ? label : "", paths[i].label, latency[i], throughput[i]);
    if (paths[i].secure) {
      const Result &plain_latency = latency[i - 1], &plain_throughput = throughput[i - 1];
      fmt::print(
          "| {:<28} | {:<21} | {:>9.2f} | {:>9.2f} | {:>8.2f} | {:>8} |\n", "", "secure / plain",
          quantile(latency[i].latencies_us, 0.5) / quantile(plain_latency.latencies_us, 0.5),
          quantile(latency[i].latencies_us, 0.99) / quantile(plain_latency.latencies_us, 0.99),
          median(throughput[i].msgs_per_s) / median(plain_throughput.msgs_per_s), "");
    }
  }
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.size() == 6 && args[0] == "--subscriber") {
    bool shared_memory = args[2] == "shm";
    int total = std::stoi(args[4]);
    if (args[3] == "image") {
      return run_subscriber<sensor_msgs::msg::Image>(args[1], shared_memory, total, args[5]);
    }
    return run_subscriber<mocap_msgs::msg::FiducialArray>(args[1], shared_memory, total, args[5]);
  }
  bool quick = !args.empty() && args[0] == "--quick";
  if (getenv("MOCAP_DOMAIN_ID") == nullptr) {
    setenv("MOCAP_DOMAIN_ID", std::to_string(200 + getpid() % 30).c_str(), 1);
  }
  // The subscriber processes read the credentials from the command line, not from these.
  unsetenv("MOCAP_SECURITY_DIRECTORY");
  unsetenv("MOCAP_SECURITY_IDENTITY");
  fs::path security = fs::temp_directory_path() / fmt::format("security_bench_{}", getpid());
  std::string script = fmt::format("bash '{}/scripts/make_security.sh' '{}' publisher subscriber",
                                   MOCAP_SOURCE_DIR, security.string());
  if (std::system((script + " > /dev/null").c_str()) != 0) {
    fmt::print(stderr, "security_bench: cannot make credentials: {}\n", script);
    return 1;
  }
  int rounds = quick ? 2 : 4;
  int scale = quick ? 4 : 1;
  std::vector<Size> sizes = {
      {"FiducialArray (12)", false, 12, 0, 1000, 4000 / scale, 20000 / scale},
      {"Image 1280x720 mono8", true, 1280, 720, 100, 800 / scale, 400 / scale},
  };
  std::string self = fs::read_symlink("/proc/self/exe").string();
  fmt::print(
      "security_bench: one hop between two processes, reliable QoS, {} cores, {} rounds with "
      "the paths interleaved.\nLatency: one-way, at the rate shown, pooled over rounds. "
      "Throughput: publishing as fast as flow control allows, median of rounds.\n\n",
      std::thread::hardware_concurrency(), rounds);
  fmt::print("| {:<28} | {:<21} | {:>9} | {:>9} | {:>8} | {:>8} |\n", "message", "path",
             "median us", "p99 us", "msgs/s", "MB/s");
  fmt::print("|{:-<30}|{:-<23}|{:-<11}|{:-<11}|{:-<10}|{:-<10}|\n", "", "", "", "", "", "");
  measure<mocap_msgs::msg::FiducialArray>(self, security.string(), sizes[0], rounds);
  measure<sensor_msgs::msg::Image>(self, security.string(), sizes[1], rounds);
  std::error_code ignored;
  fs::remove_all(security, ignored);
  return 0;
}
