// The VRPN tracker server under load: 8 boards reported at a camera's rate while 0, 1 and 10
// clients read, and the cost to the graph (the time report() takes, the report rate it keeps)
// beside the clients' latency, early and late in the run, and the time to a client's first
// report after it connects.
//   build/bin/vrpn_bench [--seconds S] [--rate HZ] [--boards N] [--clients N[,N...]]
//
// The clients are threads of this process on loopback TCP, reading with the server's own
// decoder (test/outputs/vrpn_client.mjs checks the bytes independently). Latency: from the
// report() call to the client having decoded the Pos_Quat message.
#include <arpa/inet.h>
#include <netinet/in.h>
#include <netinet/tcp.h>
#include <poll.h>
#include <sys/socket.h>
#include <unistd.h>

#include <algorithm>
#include <atomic>
#include <chrono>
#include <cstdlib>
#include <cstring>
#include <map>
#include <mutex>
#include <string>
#include <thread>
#include <vector>

#include <fmt/format.h>

#include "outputs/vrpn_server/vrpn_protocol.hpp"
#include "outputs/vrpn_server/vrpn_server.hpp"

using namespace mocap::vrpn;
using Clock = std::chrono::steady_clock;

namespace {

int64_t wall_ns() {
  return std::chrono::duration_cast<std::chrono::nanoseconds>(
             std::chrono::system_clock::now().time_since_epoch())
      .count();
}

double quantile(std::vector<double> values, double q) {
  if (values.empty()) return 0;
  std::sort(values.begin(), values.end());
  return values[static_cast<size_t>(q * static_cast<double>(values.size() - 1))];
}

struct ClientResult {
  std::vector<double> early_us, late_us;  // latencies in the first and second half of the run
  double first_report_ms = -1;
  size_t poses = 0;
};

// Connects, sends its cookie, reads until `stop`, decoding every message.
void run_client(uint16_t port, const std::atomic<bool>& stop, int64_t half_time_ns,
                ClientResult& result) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(port);
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  const auto connecting = Clock::now();
  if (::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address) != 0) {
    std::perror("connect");
    std::exit(1);
  }
  const std::string our_cookie = cookie();
  [[maybe_unused]] auto sent = ::send(fd, our_cookie.data(), our_cookie.size(), 0);
  std::string cookie_in;
  MessageReader reader;
  std::map<int32_t, std::string> types;
  char buffer[1 << 16];
  while (!stop) {
    pollfd p{fd, POLLIN, 0};
    if (::poll(&p, 1, 100) <= 0) continue;
    const ssize_t n = ::recv(fd, buffer, sizeof buffer, 0);
    if (n <= 0) break;
    std::string_view bytes(buffer, static_cast<size_t>(n));
    if (cookie_in.size() < kCookieSize) {
      const size_t take = std::min(bytes.size(), kCookieSize - cookie_in.size());
      cookie_in.append(bytes.substr(0, take));
      bytes.remove_prefix(take);
    }
    reader.feed(bytes);
    const int64_t now = wall_ns();
    while (auto message = reader.next()) {
      if (message->type == kTypeDescription) {
        types[message->sender] = described_name(*message).value_or("");
        continue;
      }
      if (types[message->type] != kPosQuatType) continue;
      if (result.first_report_ms < 0) {
        result.first_report_ms =
            std::chrono::duration<double, std::milli>(Clock::now() - connecting).count();
        continue;  // the latest report, sent on connecting: not a live one
      }
      const int64_t stamp =
          int64_t{message->seconds} * 1'000'000'000 + int64_t{message->microseconds} * 1000;
      (now < half_time_ns ? result.early_us : result.late_us)
          .push_back(static_cast<double>(now - stamp) / 1000);
      ++result.poses;
    }
  }
  ::close(fd);
}

struct Row {
  size_t clients;
  double reports_per_s, report_call_median_us, report_call_p99_us;
  std::vector<ClientResult> results;
};

Row run(size_t clients, double seconds, double rate_hz, int boards) {
  TrackerServer server({.port = 0, .max_queued_bytes = 4 << 20});
  // Every board known before the clients come, so they get a first report at once.
  for (int b = 0; b < boards; ++b) {
    server.report(fmt::format("board_{}", b), {.stamp_ns = wall_ns()});
  }
  std::atomic<bool> stop{false};
  const int64_t start_ns = wall_ns();
  const auto half_ns = start_ns + static_cast<int64_t>(seconds * 0.5e9);
  std::vector<ClientResult> results(clients);
  std::vector<std::thread> threads;
  for (size_t c = 0; c < clients; ++c) {
    threads.emplace_back(run_client, server.port(), std::cref(stop), half_ns, std::ref(results[c]));
  }
  while (server.clients() < clients) std::this_thread::sleep_for(std::chrono::milliseconds(1));

  std::vector<double> call_us;
  const auto period =
      std::chrono::duration_cast<Clock::duration>(std::chrono::duration<double>(1.0 / rate_hz));
  const auto begin = Clock::now();
  auto next = begin;
  size_t frames = 0;
  while (Clock::now() - begin < std::chrono::duration<double>(seconds)) {
    std::this_thread::sleep_until(next);
    next += period;
    for (int b = 0; b < boards; ++b) {
      TrackerReport report;
      report.stamp_ns = wall_ns();
      report.position = Eigen::Vector3d(0.1 * b, 0.01 * static_cast<double>(frames), 1.5);
      report.angular_velocity = Eigen::Vector3d(0, 0, 0.5);
      const auto called = Clock::now();
      server.report(fmt::format("board_{}", b), report);
      call_us.push_back(std::chrono::duration<double, std::micro>(Clock::now() - called).count());
    }
    ++frames;
  }
  const double elapsed = std::chrono::duration<double>(Clock::now() - begin).count();
  std::this_thread::sleep_for(std::chrono::milliseconds(200));
  stop = true;
  for (auto& thread : threads) thread.join();
  return {clients, static_cast<double>(frames) / elapsed, quantile(call_us, 0.5),
          quantile(call_us, 0.99), std::move(results)};
}

}  // namespace

int main(int argc, char** argv) {
  double seconds = 10, rate = 120;
  int boards = 8;
  std::vector<size_t> client_counts = {0, 1, 10};
  for (int i = 1; i + 1 < argc; i += 2) {
    const std::string option = argv[i];
    if (option == "--seconds") {
      seconds = std::atof(argv[i + 1]);
    } else if (option == "--rate") {
      rate = std::atof(argv[i + 1]);
    } else if (option == "--boards") {
      boards = std::atoi(argv[i + 1]);
    } else if (option == "--clients") {
      client_counts.clear();
      for (const char* p = argv[i + 1]; *p != '\0';) {
        char* end = nullptr;
        client_counts.push_back(std::strtoul(p, &end, 10));
        p = *end == ',' ? end + 1 : end;
      }
    } else {
      fmt::print(stderr,
                 "usage: vrpn_bench [--seconds S] [--rate HZ] [--boards N] [--clients N,N..]\n");
      return 2;
    }
  }
  fmt::print(
      "VRPN tracker server: {} boards at {} Hz for {} s per row; clients on loopback TCP\n\n",
      boards, rate, seconds);
  fmt::print(
      "| clients | frames/s kept | report() median µs | report() p99 µs | latency median µs "
      "(1st half / 2nd half) | latency p99 µs (1st / 2nd) | latency max µs | first report "
      "ms (max) | poses per client |\n");
  fmt::print("|---:|---:|---:|---:|---:|---:|---:|---:|---:|\n");
  for (size_t clients : client_counts) {
    const Row row = run(clients, seconds, rate, boards);
    std::vector<double> early, late, first;
    size_t poses = 0;
    for (const ClientResult& r : row.results) {
      early.insert(early.end(), r.early_us.begin(), r.early_us.end());
      late.insert(late.end(), r.late_us.begin(), r.late_us.end());
      first.push_back(r.first_report_ms);
      poses += r.poses;
    }
    std::vector<double> all = early;
    all.insert(all.end(), late.begin(), late.end());
    if (clients == 0) {
      fmt::print("| 0 | {:.1f} | {:.2f} | {:.2f} | - | - | - | - | - |\n", row.reports_per_s,
                 row.report_call_median_us, row.report_call_p99_us);
      continue;
    }
    fmt::print(
        "| {} | {:.1f} | {:.2f} | {:.2f} | {:.0f} / {:.0f} | {:.0f} / {:.0f} | {:.0f} | "
        "{:.1f} | {} |\n",
        clients, row.reports_per_s, row.report_call_median_us, row.report_call_p99_us,
        quantile(early, 0.5), quantile(late, 0.5), quantile(early, 0.99), quantile(late, 0.99),
        all.empty() ? 0.0 : *std::max_element(all.begin(), all.end()),
        *std::max_element(first.begin(), first.end()), poses / clients);
  }
  fmt::print(
      "\nframes/s kept: the reporting loop's rate (target {} Hz): what the graph keeps with "
      "the server beside it.\n",
      rate);
  return 0;
}
