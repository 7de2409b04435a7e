// The NatNet server under load: frames of 8 bodies and 100 markers reported at 120 Hz while 0, 1
// and 10 unicast clients read, and the cost to the graph (the time send_frame() takes, the frame
// rate the reporter keeps) beside the clients' latency: from the send_frame() call to the client
// having decoded the whole frame. Against a reference measured in the same run: the same bytes
// sent by plain sendto() to the same clients.
//   build/bin/natnet_bench [--seconds S] [--rate HZ] [--bodies N] [--markers N]
//
// The clients are threads of this process on loopback UDP, decoding NatNet 4.1 frames with a
// decoder of this file (test/outputs/natnet_client.mjs checks the bytes independently).
#include <arpa/inet.h>
#include <netinet/in.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "outputs/natnet_server/natnet_protocol.hpp"
#include "outputs/natnet_server/natnet_server.hpp"

using namespace mocap::natnet;

namespace {

int64_t wall_ns() { return static_cast<int64_t>(Server::now_ticks()); }

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  return values[static_cast<size_t>(q * static_cast<double>(values.size() - 1))];
}

// Reads a 4.1 frame field by field; the frame number, or -1 for what is not a whole frame.
int32_t decode_frame(const char* data, size_t size) {
  size_t at = 0;
  bool ok = true;
  auto take = [&](size_t n) {
    const size_t from = at;
    at += n;
    ok = ok && at <= size;
    return ok ? data + from : nullptr;
  };
  auto i32 = [&] {
    int32_t v = 0;
    if (const char* p = take(4)) std::memcpy(&v, p, 4);
    return v;
  };
  auto floats = [&](size_t n) {
    volatile float sink = 0;
    for (size_t i = 0; i < n && ok; ++i) {
      float v = 0;
      if (const char* p = take(4)) std::memcpy(&v, p, 4);
      sink = sink + v;
    }
  };
  uint16_t id = 0;
  std::memcpy(&id, data, 2);
  if (size < 8 || id != kFrameOfData) return -1;
  take(4);
  const int32_t frame = i32();
  int32_t sets = i32();
  i32();
  for (int32_t s = 0; s < sets && ok; ++s) {
    while (at < size && data[at] != '\0') ++at;
    take(1);
    floats(3 * static_cast<size_t>(i32()));
  }
  floats(3 * static_cast<size_t>(i32()));  // legacy markers
  i32();
  const int32_t bodies = i32();
  i32();
  for (int32_t b = 0; b < bodies && ok; ++b) {
    i32();
    floats(8);
    take(2);
  }
  for (int section = 0; section < 2; ++section) {  // skeletons, assets: none here
    i32();
    i32();
  }
  const int32_t markers = i32();
  i32();
  for (int32_t m = 0; m < markers && ok; ++m) {
    i32();
    floats(4);
    take(2);
    floats(1);
  }
  for (int section = 0; section < 2; ++section) {  // force plates, devices
    i32();
    i32();
  }
  take(4 + 4 + 8 + 24 + 8 + 2 + 4);  // suffix
  return ok && at == size ? frame : -1;
}

struct ClientResult {
  std::vector<double> latency_us;
  size_t decoded = 0, broken = 0;
};

// A client on loopback: connects to the server (port 0: none, for the plain reference), keeps
// alive, decodes every frame until `stop`. Its own address in `address` once bound.
void run_client(uint16_t port, const std::atomic<bool>& stop,
                const std::vector<std::atomic<int64_t>>& reported_ns, ClientResult& result,
                std::atomic<bool>& bound, sockaddr_in& address) {
  const int fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  const int buffer = 4 << 20;
  setsockopt(fd, SOL_SOCKET, SO_RCVBUF, &buffer, sizeof buffer);
  address.sin_family = AF_INET;
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  ::bind(fd, reinterpret_cast<sockaddr*>(&address), sizeof address);
  socklen_t length = sizeof address;
  getsockname(fd, reinterpret_cast<sockaddr*>(&address), &length);
  bound = true;
  sockaddr_in server{};
  server.sin_family = AF_INET;
  server.sin_port = htons(port);
  server.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const uint16_t header[2] = {kConnect, 0};
  if (port != 0) ::sendto(fd, header, 4, 0, reinterpret_cast<sockaddr*>(&server), sizeof server);
  std::vector<char> data(1 << 16);
  auto last_keep_alive = std::chrono::steady_clock::now();
  while (!stop) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 50) > 0) {
      const ssize_t n = ::recv(fd, data.data(), data.size(), 0);
      const int64_t now = wall_ns();
      if (n <= 0) continue;
      uint16_t id = 0;
      std::memcpy(&id, data.data(), 2);
      if (id != kFrameOfData) continue;
      const int32_t frame = decode_frame(data.data(), static_cast<size_t>(n));
      if (frame < 1 || static_cast<size_t>(frame) > reported_ns.size()) {
        ++result.broken;
        continue;
      }
      ++result.decoded;
      result.latency_us.push_back(
          static_cast<double>(now - reported_ns[static_cast<size_t>(frame - 1)].load()) * 1e-3);
    }
    if (port != 0 && std::chrono::steady_clock::now() - last_keep_alive > std::chrono::seconds(1)) {
      const uint16_t keep_alive[2] = {kKeepAlive, 0};
      ::sendto(fd, keep_alive, 4, 0, reinterpret_cast<sockaddr*>(&server), sizeof server);
      last_keep_alive = std::chrono::steady_clock::now();
    }
  }
  ::close(fd);
}

FrameOfData frame_of(int k, int bodies, int markers) {
  FrameOfData frame;
  for (int b = 0; b < bodies; ++b) {
    RigidBodyData body;
    body.id = b + 1;
    body.position = Eigen::Vector3f(0.01f * static_cast<float>(k % 100), static_cast<float>(b), 1);
    body.tracking_valid = true;
    frame.rigid_bodies.push_back(body);
  }
  for (int m = 0; m < markers; ++m) {
    LabeledMarkerData marker;
    marker.id = ((m % bodies + 1) << 16) | (m / bodies + 1);
    marker.position = Eigen::Vector3f(static_cast<float>(m), 0, 1);
    marker.flags = kHasModel;
    frame.labeled_markers.push_back(marker);
  }
  frame.stamps.camera_mid_exposure = Server::now_ticks();
  frame.stamps.camera_data_received = frame.stamps.camera_mid_exposure;
  return frame;
}

struct Row {
  int clients = 0;
  double rate_hz = 0, send_median_us = 0, send_p99_us = 0, median_us = 0, p99_us = 0;
  size_t decoded = 0, expected = 0, broken = 0, bytes = 0;
};

// Reports for `seconds` at `rate` with `clients` clients; with `plain`, the same bytes go out by
// sendto() to each client, without the server.
Row run(int clients, bool plain, double seconds, double rate, int bodies, int markers) {
  Server server({.command_port = 0});
  const auto frames = static_cast<size_t>(seconds * rate) + 1;
  std::vector<std::atomic<int64_t>> reported_ns(frames);
  std::atomic<bool> stop{false};
  std::vector<ClientResult> results(static_cast<size_t>(clients));
  std::vector<std::atomic<bool>> bound(static_cast<size_t>(clients));
  std::vector<sockaddr_in> addresses(static_cast<size_t>(clients));
  std::vector<std::thread> threads;
  for (size_t c = 0; c < results.size(); ++c) {
    threads.emplace_back(run_client, plain ? uint16_t{0} : server.command_port(), std::cref(stop),
                         std::cref(reported_ns), std::ref(results[c]), std::ref(bound[c]),
                         std::ref(addresses[c]));
  }
  for (size_t c = 0; c < results.size(); ++c) {
    while (!bound[c]) std::this_thread::sleep_for(std::chrono::milliseconds(1));
  }
  while (!plain && server.clients() < static_cast<size_t>(clients)) {
    std::this_thread::sleep_for(std::chrono::milliseconds(10));
  }
  const int plain_fd = ::socket(AF_INET, SOCK_DGRAM, 0);
  std::vector<double> send_us;
  const auto period = std::chrono::duration<double>(1.0 / rate);
  const size_t bytes = encode_frame(frame_of(0, bodies, markers), kDefaultVersion).size();
  const auto start = std::chrono::steady_clock::now();
  for (size_t k = 0; k < frames; ++k) {
    std::this_thread::sleep_until(start + k * period);
    FrameOfData frame = frame_of(static_cast<int>(k), bodies, markers);
    const int64_t before = wall_ns();
    reported_ns[k] = before;
    if (!plain) {
      server.send_frame(std::move(frame));
    } else {
      frame.frame_number = static_cast<int32_t>(k + 1);
      const std::string packet = encode_frame(frame, kDefaultVersion);
      for (const sockaddr_in& to : addresses) {
        ::sendto(plain_fd, packet.data(), packet.size(), MSG_DONTWAIT,
                 reinterpret_cast<const sockaddr*>(&to), sizeof to);
      }
    }
    send_us.push_back(static_cast<double>(wall_ns() - before) * 1e-3);
  }
  const double elapsed =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  std::this_thread::sleep_for(std::chrono::milliseconds(100));
  stop = true;
  for (std::thread& thread : threads) thread.join();
  ::close(plain_fd);
  Row row;
  row.clients = clients;
  row.rate_hz = static_cast<double>(frames - 1) / elapsed;
  row.send_median_us = quantile(send_us, 0.5);
  row.send_p99_us = quantile(send_us, 0.99);
  std::vector<double> latency;
  for (const ClientResult& result : results) {
    latency.insert(latency.end(), result.latency_us.begin(), result.latency_us.end());
    row.decoded += result.decoded;
    row.broken += result.broken;
  }
  row.expected = frames * static_cast<size_t>(clients);
  row.median_us = quantile(latency, 0.5);
  row.p99_us = quantile(latency, 0.99);
  row.bytes = bytes;
  return row;
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 10, rate = 120;
  int bodies = 8, markers = 100;
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string flag = argv[i];
    if (flag == "--seconds")
      seconds = std::atof(argv[i + 1]);
    else if (flag == "--rate")
      rate = std::atof(argv[i + 1]);
    else if (flag == "--bodies")
      bodies = std::atoi(argv[i + 1]);
    else if (flag == "--markers")
      markers = std::atoi(argv[i + 1]);
    else {
      fmt::print(stderr, "natnet_bench: unknown flag {}\n", flag);
      return 2;
    }
  }
  fmt::print(
      "NatNet server: {} bodies, {} markers a frame at {} Hz for {} s per row, NatNet {}.{}\n",
      bodies, markers, rate, seconds, kDefaultVersion.major, kDefaultVersion.minor);
  fmt::print(
      "| sent by | clients | frame bytes | frames/s kept | send median / p99 (us) | "
      "report -> decoded median / p99 (us) | frames decoded |\n");
  fmt::print("|---|---|---|---|---|---|---|\n");
  for (const auto& [clients, plain] :
       {std::pair{0, false}, {1, false}, {10, false}, {1, true}, {10, true}}) {
    const Row row = run(clients, plain, seconds, rate, bodies, markers);
    fmt::print(
        "| {} | {} | {} | {:.2f} | {:.1f} / {:.1f} | {} | {} of {}{} |\n",
        plain ? "plain sendto (reference)" : "natnet_server", row.clients, row.bytes, row.rate_hz,
        row.send_median_us, row.send_p99_us,
        clients == 0 ? std::string("-") : fmt::format("{:.1f} / {:.1f}", row.median_us, row.p99_us),
        row.decoded, row.expected,
        row.broken > 0 ? fmt::format(" ({} broken)", row.broken) : std::string());
  }
  fmt::print(
      "target: report -> decoded <= 500 us median with 10 clients at 120 Hz; frames/s kept "
      "at {} with 0, 1 and 10 clients\n",
      rate);
  return 0;
}
