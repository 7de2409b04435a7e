// Camera images between hosts: one 1280x720 mono8 hop over UDP at 100 Hz through the runtime,
// for each pair of DDS implementations (publisher -> subscriber), between two processes of this
// machine (loopback) and between two network-namespace hosts joined by a veth link (as two
// machines on a switch; needs root) with Ethernet's MTU and with jumbo frames. Shared memory is off
// for Fast DDS, so every image crosses UDP as it does between machines. The reference: the same
// bytes through plain UDP sockets on the same paths. All measured in this run, the paths
// interleaved.
//
//   build/bin/image_hop_bench [--quick]
//
// One-way latency: the publisher stamps each image with CLOCK_MONOTONIC just before
// publishing, the subscriber subtracts it from its own reading on arrival (network namespaces
// share the kernel's clock). Target: median <= 1 ms on every path (issue: a tracking volume).

#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <cerrno>
#include <cstdlib>
#include <cstring>
#include <filesystem>
#include <fstream>
#include <map>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>
#include <mocap/component_host.hpp>
#include <sensor_msgs/msg/image.hpp>

#include "bench/one_hop.hpp"
#include "test/test_support.hpp"

namespace {

using namespace mocap::one_hop;
using Image = sensor_msgs::msg::Image;

constexpr int kRateHz = 100;
const Size kImage{"Image 1280x720 mono8", true, 1280, 720, kRateHz, 0, 0};

mocap::HostOptions udp_host(const std::string& name, const std::string& implementation) {
  return {.name = name,
          .threads = 2,
          .dds = {.implementation = implementation, .shared_memory = false}};
}

// --- the two processes ------------------------------------------------------------------

int run_subscriber(const std::string& implementation, int total, const std::string& out) {
  mocap::ComponentHost host(udp_host("image_subscriber", implementation));
  host.add(kSubscriberFactory<Image>, {.name = "subscriber"});
  host.start();
  // Tells the publisher, through a file beside `out`, that the path is open.
  if (received.wait_primed(std::chrono::seconds(60))) std::ofstream(out + ".ready");
  received.wait_for(total, std::chrono::seconds(120));
  host.stop();
  std::lock_guard lock(received.mutex);
  std::ofstream file(out);
  file << received.count << "\n";
  for (double latency : received.latencies_us) file << latency << "\n";
  return 0;
}

int run_publisher(const std::string& implementation, int count, const std::string& out) {
  mocap::ComponentHost host(udp_host("image_publisher", implementation));
  auto& publisher =
      static_cast<BenchPublisher<Image>&>(host.add(kPublisherFactory<Image>, {.name = "pub"}));
  host.start();
  for (int i = 0; i < 1000 && publisher.publisher.matched_subscribers() == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  // Priming images until the subscriber has one: each side may see the other first.
  Image priming = prototype<Image>(kImage);
  priming.header().frame_id(kPrimingFrame);
  for (int i = 0; i < 1000 && !std::filesystem::exists(out + ".ready"); ++i) {
    publisher.publisher.publish(std::make_shared<Image>(priming));
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  auto image = std::make_shared<Image>(prototype<Image>(kImage));
  publish_all(count, kRateHz, [&] {
    stamp(*image);
    publisher.publisher.publish(image);
    return stamp_ns(*image);
  });
  // Until the subscriber has everything (reliable): stopping now would drop the last ones.
  for (int i = 0; i < 3000 && !std::filesystem::exists(out); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  host.stop();
  return 0;
}

// --- the reference: the same bytes through plain UDP sockets ---------------------------
// Each image in datagrams of at most `datagram` bytes, each with a header (image number, byte
// offset, the publisher's stamp); unreliable, so an image counts only when all its bytes came.
// What the kernel's path alone costs: no DDS, no serialization, no acknowledgements.

struct ChunkHeader {
  uint32_t image;
  uint32_t offset;
  int64_t stamp_ns;
};
constexpr int kRawPort = 7399;                                    // below every DDS domain's ports
const size_t kImageBytes = size_t{kImage.width} * kImage.height;  // mono8

int udp_socket(int buffer_bytes) {
  const int fd = socket(AF_INET, SOCK_DGRAM | SOCK_CLOEXEC, 0);
  if (fd < 0) return -1;
  // As root past net.core.[rw]mem_max, as a DDS implementation's configured buffers are not.
  setsockopt(fd, SOL_SOCKET, SO_RCVBUFFORCE, &buffer_bytes, sizeof buffer_bytes);
  setsockopt(fd, SOL_SOCKET, SO_SNDBUFFORCE, &buffer_bytes, sizeof buffer_bytes);
  return fd;
}

int run_raw_subscriber(int total, const std::string& out) {
  const int fd = udp_socket(8 << 20);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(kRawPort);
  address.sin_addr.s_addr = htonl(INADDR_ANY);
  if (fd < 0 || bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    fmt::print(stderr, "plain UDP subscriber: cannot bind port {}\n", kRawPort);
    return 1;
  }
  std::ofstream(out + ".ready");
  std::map<uint32_t, size_t> bytes;  // of the images still incomplete
  std::vector<double> latencies_us;
  int complete = 0;
  std::vector<char> buffer(65536);
  for (;;) {
    pollfd ready{fd, POLLIN, 0};
    if (poll(&ready, 1, 3000) <= 0) break;  // the publisher is done
    const ssize_t n = recv(fd, buffer.data(), buffer.size(), 0);
    if (n < ssize_t(sizeof(ChunkHeader))) continue;
    ChunkHeader header;
    std::memcpy(&header, buffer.data(), sizeof header);
    size_t& got = bytes[header.image];
    got += size_t(n) - sizeof header;
    if (got < kImageBytes) continue;
    const int64_t now = steady_ns();
    bytes.erase(header.image);
    if (int(header.image) >= kWarmup) latencies_us.push_back(double(now - header.stamp_ns) / 1e3);
    if (++complete == total) break;
  }
  close(fd);
  std::ofstream file(out);
  file << complete << "\n";
  for (double latency : latencies_us) file << latency << "\n";
  return 0;
}

int run_raw_publisher(const std::string& to, int datagram, int count, const std::string& out) {
  const int fd = udp_socket(8 << 20);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(kRawPort);
  if (fd < 0 || inet_pton(AF_INET, to.c_str(), &address.sin_addr) != 1 ||
      connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    fmt::print(stderr, "plain UDP publisher: cannot reach {}:{}\n", to, kRawPort);
    return 1;
  }
  for (int i = 0; i < 1000 && !std::filesystem::exists(out + ".ready"); ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const std::vector<char> image(kImageBytes, 7);
  const size_t payload = size_t(datagram) - sizeof(ChunkHeader);
  std::vector<char> packet(static_cast<size_t>(datagram));
  uint32_t number = 0;
  publish_all(count, kRateHz, [&] {
    const ChunkHeader first{number, 0, steady_ns()};
    for (size_t offset = 0; offset < kImageBytes; offset += payload) {
      ChunkHeader header = first;
      header.offset = uint32_t(offset);
      const size_t size = std::min(payload, kImageBytes - offset);
      std::memcpy(packet.data(), &header, sizeof header);
      std::memcpy(packet.data() + sizeof header, image.data() + offset, size);
      while (send(fd, packet.data(), sizeof header + size, 0) < 0 && errno == ENOBUFS) {
      }
    }
    ++number;
    return first.stamp_ns;
  });
  close(fd);
  return 0;
}

// --- the orchestrating process ----------------------------------------------------------

struct Path {
  std::string publisher, subscriber;  // implementations
  int mtu;                            // of the link between two namespace hosts; 0: loopback
  int datagram = 0;                   // > 0: plain UDP sockets, datagrams of this size
  std::string label() const {
    return fmt::format("{}, {}",
                       datagram > 0 ? fmt::format("plain UDP, {} B datagrams", datagram)
                                    : publisher + " -> " + subscriber,
                       mtu > 0 ? fmt::format("hosts, MTU {}", mtu) : "loopback");
  }
};

struct Result {
  std::vector<double> latencies_us;
  int delivered = 0, expected = 0;
};

void measure(const std::string& self, const Path& path, const mocap::test::TwoHosts* hosts,
             int count, Result& result) {
  const mocap::test::TempDir dir;
  const std::string out = (dir / "received.txt").string();
  auto on = [&](bool host_b, std::vector<std::string> argv) {
    if (hosts == nullptr) return argv;
    return host_b ? hosts->on_b(std::move(argv)) : hosts->on_a(std::move(argv));
  };
  const int total = kWarmup + count;
  std::vector<std::string> subscribe = {self, "--subscriber", path.subscriber,
                                        std::to_string(total), out};
  std::vector<std::string> publish = {self, "--publisher", path.publisher, std::to_string(count),
                                      out};
  if (path.datagram > 0) {
    subscribe = {self, "--raw-subscriber", std::to_string(total), out};
    publish = {self,
               "--raw-publisher",
               hosts == nullptr ? "127.0.0.1" : hosts->address_b(),
               std::to_string(path.datagram),
               std::to_string(count),
               out};
  }
  mocap::test::ChildProcess subscriber(on(true, subscribe), {}, dir / "subscriber.log");
  mocap::test::ChildProcess publisher(on(false, publish), {}, dir / "publisher.log");
  subscriber.wait(std::chrono::seconds(300));
  publisher.wait(std::chrono::seconds(60));
  std::ifstream in(out);
  int delivered = 0;
  in >> delivered;
  for (double latency; in >> latency;) result.latencies_us.push_back(latency);
  result.delivered += delivered;
  result.expected += total;
}

}  // namespace

int main(int argc, char** argv) {
  std::vector<std::string> args(argv + 1, argv + argc);
  if (args.size() == 4 && args[0] == "--subscriber") {
    return run_subscriber(args[1], std::stoi(args[2]), args[3]);
  }
  if (args.size() == 4 && args[0] == "--publisher") {
    return run_publisher(args[1], std::stoi(args[2]), args[3]);
  }
  if (args.size() == 3 && args[0] == "--raw-subscriber") {
    return run_raw_subscriber(std::stoi(args[1]), args[2]);
  }
  if (args.size() == 5 && args[0] == "--raw-publisher") {
    return run_raw_publisher(args[1], std::stoi(args[2]), std::stoi(args[3]), args[4]);
  }
  const bool quick = !args.empty() && args[0] == "--quick";
  if (getenv("MOCAP_DOMAIN_ID") == nullptr) {
    setenv("MOCAP_DOMAIN_ID", std::to_string(200 + getpid() % 30).c_str(), 1);
  }
  const int rounds = quick ? 1 : 3;
  const int count = quick ? 300 : 500;
  const std::string self = std::filesystem::read_symlink("/proc/self/exe").string();
  const mocap::test::TwoHosts hosts;
  std::vector<Path> paths;
  // Ethernet's 1500 bytes, and the jumbo frames of a camera network (GigE Vision's 9000).
  for (int mtu : {0, 1500, 9000}) {
    if (mtu > 0 && !hosts.error().empty()) continue;
    for (const char* publisher : {"fastdds", "cyclonedds"}) {
      for (const char* subscriber : {"fastdds", "cyclonedds"}) {
        paths.push_back({publisher, subscriber, mtu});
      }
    }
    // The floor: as DDS sends (64,000-byte datagrams the kernel cuts into IP fragments), and
    // as a camera protocol does (datagrams that fit the link's MTU; the loopback's is 65,536).
    paths.push_back({"", "", mtu, 64000});
    if (mtu > 0) paths.push_back({"", "", mtu, mtu - 28});
  }
  std::map<std::string, Result> results;
  for (int round = 0; round < rounds; ++round) {
    for (size_t turn = 0; turn < paths.size(); ++turn) {
      const Path& path = paths[(turn + size_t(round)) % paths.size()];
      if (path.mtu > 0) hosts.set_mtu(path.mtu);
      measure(self, path, path.mtu > 0 ? &hosts : nullptr, count, results[path.label()]);
    }
  }
  fmt::print(
      "image_hop_bench: {} at {} Hz over UDP through the runtime (Fast DDS's shared memory "
      "off), {} cores, {} round(s) of {} images a path, the paths interleaved.{}\n\n",
      kImage.label, kRateHz, std::thread::hardware_concurrency(), rounds, count,
      hosts.error().empty() ? std::string()
                            : " No namespace hosts (" + hosts.error() + "): loopback only.");
  fmt::print("| {:<46} | {:>9} | {:>9} | {:>12} |\n", "publisher -> subscriber, where", "median us",
             "p99 us", "delivered");
  fmt::print("|{:-<48}|{:-<11}|{:-<11}|{:-<14}|\n", "", "", "", "");
  // Per place: the fastest and slowest median of the DDS paths, and the plain sockets' best.
  std::map<int, std::pair<double, double>> spread;
  std::map<int, double> floor;
  for (const Path& path : paths) {
    const Result& r = results[path.label()];
    const double median = quantile(r.latencies_us, 0.5);
    if (path.datagram > 0) {
      auto [it, fresh] = floor.try_emplace(path.mtu, median);
      it->second = std::min(it->second, median);
    } else {
      auto [it, fresh] = spread.try_emplace(path.mtu, median, median);
      it->second = {std::min(it->second.first, median), std::max(it->second.second, median)};
    }
    fmt::print("| {:<46} | {:>9.1f} | {:>9.1f} | {:>12} |\n", path.label(), median,
               quantile(r.latencies_us, 0.99), fmt::format("{} of {}", r.delivered, r.expected));
  }
  fmt::print(
      "\ntargets: median <= 1000 us on every path; per place, the slowest pair of "
      "implementations within 1.5 x the fastest:");
  for (const auto& [mtu, fastest_slowest] : spread) {
    fmt::print(" {} {:.2f} x;", mtu > 0 ? fmt::format("MTU {}", mtu) : "loopback",
               fastest_slowest.second / fastest_slowest.first);
  }
  fmt::print("\nthe fastest DDS pair against the plain sockets' best median, per place:");
  for (const auto& [mtu, fastest_slowest] : spread) {
    fmt::print(" {} {:.2f} x;", mtu > 0 ? fmt::format("MTU {}", mtu) : "loopback",
               fastest_slowest.first / floor[mtu]);
  }
  fmt::print("\n");
  return 0;
}
