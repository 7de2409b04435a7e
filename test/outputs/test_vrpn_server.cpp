// The VRPN tracker server: its bytes against sequences laid out by hand from VRPN's protocol
// description, and the server against a client written separately from it
// (vrpn_client.mjs: its own decoding), connecting both ways VRPN's client library does; slow
// and broken clients dropped while others go on.
#include <gtest/gtest.h>

#include <arpa/inet.h>
#include <netinet/in.h>
#include <sys/socket.h>
#include <unistd.h>

#include <atomic>
#include <chrono>
#include <cmath>
#include <csignal>
#include <filesystem>
#include <map>
#include <memory>
#include <optional>
#include <sstream>
#include <stdexcept>
#include <string>
#include <thread>

#include <fmt/format.h>
#include <nlohmann/json.hpp>

#include "outputs/vrpn_server/vrpn_protocol.hpp"
#include "outputs/vrpn_server/vrpn_server.hpp"
#include "test/test_support.hpp"

namespace mocap::vrpn {
namespace {

using nlohmann::json;

std::string bytes(std::initializer_list<int> values) {
  std::string out;
  for (int value : values) out += static_cast<char>(value);
  return out;
}

TEST(VrpnProtocol, TheCookieIsVersion0738WithoutLogging) {
  EXPECT_EQ(cookie(), std::string("vrpn: ver. 07.38  0") + std::string(5, '\0'));
  EXPECT_EQ(check_cookie(cookie()), CookieCheck::Same);
  EXPECT_EQ(check_cookie(std::string("vrpn: ver. 07.35  0") + std::string(5, '\0')),
            CookieCheck::OtherMinorVersion);
  EXPECT_EQ(check_cookie(std::string("vrpn: ver. 08.00  0") + std::string(5, '\0')),
            CookieCheck::NotVrpn);
  EXPECT_EQ(check_cookie("GET / HTTP/1.1\r\nHost: x\r\n"), CookieCheck::NotVrpn);
}

// Laid out by hand: length 24 + 12, seconds, microseconds, sender 3, type -1, sequence 7; the
// name's length with its NUL, the name, the NUL, zeros to a multiple of 8.
TEST(VrpnProtocol, ASenderDescriptionByteForByte) {
  Message message = description(kSenderDescription, 3, "board_a");
  message.seconds = 0x01020304;
  message.microseconds = 0x000A0B0C;
  message.sequence = 7;
  const std::string expected =
      bytes({0, 0, 0,    36,   1,    2,    3, 4, 0, 0x0A, 0x0B, 0x0C, 0, 0,
             0, 3, 0xFF, 0xFF, 0xFF, 0xFF, 0, 0, 0, 7,    0,    0,    0, 8}) +
      "board_a" + std::string(1 + 4, '\0');
  EXPECT_EQ(encode(message), expected);
  EXPECT_EQ(described_name(message), "board_a");
}

// Sensor 0 twice, then big-endian doubles: 1, -2, 0.5 and the quaternion (0, 0, 0, 1).
TEST(VrpnProtocol, APosQuatReportByteForByte) {
  Message message;
  message.sender = 0;
  message.type = 5;
  message.payload =
      pos_quat_payload(0, Eigen::Vector3d(1, -2, 0.5), Eigen::Quaterniond::Identity());
  const std::string zero(8, '\0');
  const std::string expected =
      bytes({0, 0, 0, 88, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 5, 0, 0, 0, 0}) +
      std::string(8, '\0') + bytes({0x3F, 0xF0, 0, 0, 0, 0, 0, 0}) +
      bytes({0xC0, 0x00, 0, 0, 0, 0, 0, 0}) + bytes({0x3F, 0xE0, 0, 0, 0, 0, 0, 0}) + zero + zero +
      zero + bytes({0x3F, 0xF0, 0, 0, 0, 0, 0, 0});
  EXPECT_EQ(encode(message), expected);
}

TEST(VrpnProtocol, TheReaderTakesMessagesInPiecesOfAnySizeAndRefusesAnImpossibleLength) {
  std::string stream;
  for (int i = 0; i < 20; ++i) {
    Message message = description(kTypeDescription, i, std::string(static_cast<size_t>(i), 'x'));
    message.sequence = static_cast<uint32_t>(i);
    stream += encode(message);
  }
  MessageReader reader;
  std::vector<Message> got;
  for (char byte : stream) {
    reader.feed(std::string_view(&byte, 1));
    while (auto message = reader.next()) got.push_back(*message);
  }
  ASSERT_EQ(got.size(), 20u);
  for (int i = 0; i < 20; ++i) {
    EXPECT_EQ(got[static_cast<size_t>(i)].sender, i);
    EXPECT_EQ(described_name(got[static_cast<size_t>(i)]),
              std::string(static_cast<size_t>(i), 'x'));
  }
  EXPECT_EQ(reader.buffered_bytes(), 0u);

  MessageReader broken;
  broken.feed(bytes({0, 0, 0, 3}) + std::string(20, '\0'));
  EXPECT_FALSE(broken.next());
  EXPECT_EQ(broken.error(), "a message of 3 bytes (at least 24, at most 65536)");
}

// --- the server and an independent client -----------------------------------------------------

// Board poses reported at 100 Hz while a test runs: board_a turning about z, board_b still.
class Reporter {
 public:
  explicit Reporter(TrackerServer& server) : server_(server) {
    thread_ = std::thread([this] {
      for (int k = 0; !stop_; ++k) {
        server_.report("board_a", board_a(k));
        server_.report("board_b", board_b(k));
        std::this_thread::sleep_for(std::chrono::milliseconds(10));
      }
    });
  }
  ~Reporter() {
    stop_ = true;
    thread_.join();
  }

  static TrackerReport board_a(int k) {
    TrackerReport report;
    report.stamp_ns = 1'700'000'000'000'000'000 + int64_t{k} * 10'000'000 + 123'000;
    report.position = Eigen::Vector3d(0.1 * k, -1.25, 2.5);
    report.orientation = Eigen::AngleAxisd(0.01 * k, Eigen::Vector3d(1, 2, 3).normalized());
    report.linear_velocity = Eigen::Vector3d(10, 0, 0);
    report.angular_velocity = Eigen::Vector3d(0, 0, 1.5);
    return report;
  }
  static TrackerReport board_b(int k) {
    TrackerReport report;
    report.stamp_ns = 1'700'000'000'000'000'000 + int64_t{k} * 10'000'000;
    report.position = Eigen::Vector3d(-3, 4, 0.75);
    return report;
  }

 private:
  TrackerServer& server_;
  std::atomic<bool> stop_{false};
  std::thread thread_;
};

std::vector<json> client(const std::string& mode, uint16_t port, int count) {
  auto [code, output] = test::run_command(
      {"node", (test::source_dir() / "test" / "outputs" / "vrpn_client.mjs").string(), mode,
       "127.0.0.1", std::to_string(port), std::to_string(count), "board_a", "board_b"},
      {}, std::chrono::seconds(60));
  EXPECT_EQ(code, 0) << output;
  std::vector<json> events;
  std::istringstream lines(output);
  for (std::string line; std::getline(lines, line);) {
    if (!line.empty() && line[0] == '{') events.push_back(json::parse(line));
  }
  return events;
}

// What the client decoded equals what was reported: positions and quaternions exactly (they
// travel as doubles), stamps to the microsecond, the angular velocity from the rotation over dt.
void expect_reports_as_sent(const std::vector<json>& events) {
  int poses = 0, velocities = 0, pongs = 0;
  for (const json& event : events) {
    if (event["event"] == "pong") ++pongs;
    if (event["event"] != "pose" && event["event"] != "velocity") continue;
    const bool a = event["tracker"] == "board_a";
    ASSERT_TRUE(a || event["tracker"] == "board_b") << event;
    // Which report: the stamp says.
    const int64_t stamp_us = event["sec"].get<int64_t>() * 1'000'000 + event["usec"].get<int64_t>();
    const int k = static_cast<int>((stamp_us * 1000 - 1'700'000'000'000'000'000) / 10'000'000);
    const TrackerReport sent = a ? Reporter::board_a(k) : Reporter::board_b(k);
    EXPECT_EQ(stamp_us, sent.stamp_ns / 1000) << event;
    if (event["event"] == "pose") {
      ++poses;
      EXPECT_EQ(event["sensor"], 0);
      for (int i = 0; i < 3; ++i) EXPECT_EQ(event["position"][i], sent.position[i]) << event;
      const Eigen::Quaterniond q = sent.orientation.normalized();
      const double expected[4] = {q.x(), q.y(), q.z(), q.w()};
      for (int i = 0; i < 4; ++i) EXPECT_EQ(event["quat"][i], expected[i]) << event;
    } else {
      ++velocities;
      for (int i = 0; i < 3; ++i) EXPECT_EQ(event["velocity"][i], sent.linear_velocity[i]);
      const Eigen::Quaterniond turn(event["quat"][3], event["quat"][0], event["quat"][1],
                                    event["quat"][2]);
      const Eigen::AngleAxisd angle_axis(turn);
      const Eigen::Vector3d angular =
          angle_axis.axis() * angle_axis.angle() / event["dt"].get<double>();
      EXPECT_TRUE(angular.isApprox(sent.angular_velocity, 1e-9) ||
                  (sent.angular_velocity.isZero() && angular.norm() < 1e-12))
          << event;
    }
  }
  EXPECT_GE(poses, 20);
  EXPECT_GE(velocities, 20);
  EXPECT_EQ(pongs, 2);
}

TEST(VrpnServer, AClientConnectingStraightToTheTcpPortGetsEveryBoard) {
  TrackerServer server({.port = 0});
  Reporter reporter(server);
  const std::vector<json> events = client("--tcp", server.port(), 10);
  ASSERT_FALSE(events.empty());
  EXPECT_EQ(events[0], (json{{"event", "cookie"}, {"text", "vrpn: ver. 07.38  0"}}));
  expect_reports_as_sent(events);
}

TEST(VrpnServer, AClientAskingOverUdpIsConnectedBack) {
  TrackerServer server({.port = 0});
  Reporter reporter(server);
  const std::vector<json> events = client("--lob", server.port(), 10);
  expect_reports_as_sent(events);
  EXPECT_EQ(server.stats().connection_requests, 1u);
}

int connect_to(uint16_t port) {
  const int fd = ::socket(AF_INET, SOCK_STREAM, 0);
  sockaddr_in address{};
  address.sin_family = AF_INET;
  address.sin_port = htons(port);
  address.sin_addr.s_addr = htonl(INADDR_LOOPBACK);
  EXPECT_EQ(::connect(fd, reinterpret_cast<sockaddr*>(&address), sizeof address), 0);
  return fd;
}

// A client that completes the handshake and then reads nothing fills its queue and is dropped;
// one that is not VRPN is refused; another client meanwhile gets every board.
TEST(VrpnServer, SlowAndForeignClientsAreDroppedWhileOthersGoOn) {
  TrackerServer server({.port = 0, .max_queued_bytes = 64 * 1024});
  Reporter reporter(server);
  const int silent = connect_to(server.port());
  ASSERT_EQ(::send(silent, cookie().data(), kCookieSize, 0), static_cast<ssize_t>(kCookieSize));
  const int foreign = connect_to(server.port());
  const std::string http = "GET / HTTP/1.1\r\nHost: localhost\r\n\r\n";
  ASSERT_EQ(::send(foreign, http.data(), http.size(), 0), static_cast<ssize_t>(http.size()));

  expect_reports_as_sent(client("--tcp", server.port(), 10));
  // The silent one: the kernel's buffers (megabytes on loopback), then 64 KiB of queue, then it
  // goes. 40,000 reports of about 200 bytes fill them all; report() never waits meanwhile.
  for (int i = 0; i < 40'000; ++i) server.report("board_c", Reporter::board_b(i));
  for (int i = 0; i < 100 && server.stats().clients_too_slow == 0; ++i) {
    std::this_thread::sleep_for(std::chrono::milliseconds(100));
  }
  const TrackerServerStats stats = server.stats();
  EXPECT_EQ(stats.clients_too_slow, 1u);
  EXPECT_EQ(stats.clients_refused, 1u);
  EXPECT_EQ(stats.pongs, 2u);
  // Both sockets were closed by the server: reading ends (after what was sent, for the silent
  // one) with end of file or a reset.
  char buffer[4096];
  ssize_t n = 0;
  while ((n = ::recv(foreign, buffer, sizeof buffer, 0)) > 0) {
  }
  EXPECT_LE(n, 0);
  ::close(foreign);
  ::close(silent);
}

// vrpn_server on host A of two network namespaces: by default only A itself may connect; with
// address 0.0.0.0 in the launch file, B may too, and the server says so once.
TEST(VrpnServer, ListensOnThisMachineOnlyUnlessTheLaunchFileOpensIt) {
  test::TwoHosts hosts;
  if (!hosts.error().empty()) GTEST_SKIP() << "cannot make network namespaces: " << hosts.error();
  test::TempDir dir;
  const std::string client_script =
      (test::source_dir() / "test" / "outputs" / "vrpn_client.mjs").string();
  auto launch = [&](const std::string& parameters, const std::string& name) {
    const std::filesystem::path file = dir / (name + ".yaml");
    test::write_file(file,
                     "groups:\n  - name: g\n    components:\n      - plugin: vrpn_server\n"
                     "        name: vrpn\n        parameters: {" +
                         parameters + "}\n");
    return std::make_unique<test::ChildProcess>(
        hosts.on_a({(test::bin_dir() / "mocap_launch").string(), file.string()}),
        std::map<std::string, std::string>{
            {"MOCAP_DOMAIN_ID", std::to_string(test::test_domain(73))}},
        dir / (name + ".log"));
  };
  auto cookie_from = [&](const std::vector<std::string>& prefix, const std::string& address) {
    std::vector<std::string> argv = prefix;
    for (const std::string& arg :
         {std::string("node"), client_script, std::string("--tcp"), address, std::string("3883"),
          std::string("0"), std::string("board_a")}) {
      argv.push_back(arg);
    }
    return test::run_command(argv, {}, std::chrono::seconds(30));
  };
  {
    auto graph = launch("", "closed");
    ASSERT_TRUE(graph->wait_for_output("VRPN trackers", std::chrono::seconds(30)))
        << graph->output();
    EXPECT_NE(graph->output().find("on 127.0.0.1:3883 TCP and UDP"), std::string::npos);
    EXPECT_EQ(cookie_from(hosts.on_a({}), "127.0.0.1").first, 0);
    const auto [code, output] = cookie_from(hosts.on_b({}), hosts.address_a());
    EXPECT_EQ(code, 1);
    EXPECT_NE(output.find("ECONNREFUSED"), std::string::npos) << output;
  }
  auto graph = launch("address: 0.0.0.0", "open");
  ASSERT_TRUE(graph->wait_for_output("VRPN trackers", std::chrono::seconds(30))) << graph->output();
  const auto [code, output] = cookie_from(hosts.on_b({}), hosts.address_a());
  EXPECT_EQ(code, 0) << output;
  EXPECT_NE(output.find("vrpn: ver. 07.38"), std::string::npos) << output;
  const std::string log = graph->output();
  const std::string warning = "Open to the network: any host that reaches port 3883 may connect";
  EXPECT_NE(log.find(warning), std::string::npos) << log;
  EXPECT_EQ(log.find(warning), log.rfind(warning)) << log;
}

// A request from host B naming host A (the server's own host, where a service listens that
// only A should reach): the server connects back to B, whose datagram it was, and only once
// however often B asks while that connection is under way; A's service sees nothing.
TEST(VrpnServer, ConnectsBackOnlyToTheRequestsSource) {
  test::TwoHosts hosts;
  if (!hosts.error().empty()) GTEST_SKIP() << "cannot make network namespaces: " << hosts.error();
  test::TempDir dir;
  const std::string probe =
      (test::source_dir() / "test" / "outputs" / "connect_back_probe.mjs").string();
  const std::filesystem::path file = dir / "open.yaml";
  test::write_file(file,
                   "groups:\n  - name: g\n    components:\n      - plugin: vrpn_server\n"
                   "        name: vrpn\n        parameters: {address: 0.0.0.0}\n");
  test::ChildProcess graph(hosts.on_a({(test::bin_dir() / "mocap_launch").string(), file.string()}),
                           {{"MOCAP_DOMAIN_ID", std::to_string(test::test_domain(37))}},
                           dir / "graph.log");
  ASSERT_TRUE(graph.wait_for_output("VRPN trackers", std::chrono::seconds(30))) << graph.output();
  test::ChildProcess on_a(hosts.on_a({"node", probe, "listen", "4500", "4"}), {}, dir / "a.log");
  test::ChildProcess on_b(hosts.on_b({"node", probe, "listen", "4500", "4"}), {}, dir / "b.log");
  std::this_thread::sleep_for(std::chrono::milliseconds(500));  // both listening
  const auto [code, output] =
      test::run_command(hosts.on_b({"node", probe, "lob", hosts.address_a(), "3883",
                                    hosts.address_a() + " 4500", "5"}),
                        {}, std::chrono::seconds(30));
  ASSERT_EQ(code, 0) << output;
  ASSERT_EQ(on_a.wait(std::chrono::seconds(20)), 0) << on_a.output();
  ASSERT_EQ(on_b.wait(std::chrono::seconds(20)), 0) << on_b.output();
  EXPECT_EQ(json::parse(on_a.output()), (json{{"connections", 0}, {"from", json::array()}}));
  EXPECT_EQ(json::parse(on_b.output()),
            (json{{"connections", 1}, {"from", json::array({hosts.address_a()})}}));
  graph.signal(SIGINT);
  ASSERT_EQ(graph.wait(std::chrono::seconds(30)), 0) << graph.output();
  EXPECT_NE(graph.output().find("5 connection requests (0 malformed, 5 naming another host than "
                                "their source, 4 not followed)"),
            std::string::npos)
      << graph.output();
}

TEST(VrpnServer, BadAddressesAreNamed) {
  try {
    TrackerServer server({.address = "localhost"});
    ADD_FAILURE() << "accepted a host name";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "TrackerServerOptions::address: 'localhost' is not an IPv4 address");
  }
  TrackerServer first({.port = 0});
  EXPECT_TRUE(first.loopback_only());
  try {
    TrackerServer second({.port = first.port()});
    ADD_FAILURE() << "two servers on one port";
  } catch (const std::runtime_error& e) {
    EXPECT_EQ(std::string(e.what()),
              fmt::format("address/port: cannot listen on TCP 127.0.0.1:{}: Address already in use",
                          first.port()));
  }
}

// Options built in code get the checks a launch file's parameters get from the plugin's ranges:
// the server refuses them before it listens, naming the field.
TEST(TrackerServerOptions, NameTheFieldThatCannotBeUsed) {
  EXPECT_EQ(TrackerServerOptions{}.problem(), std::nullopt);
  EXPECT_EQ(TrackerServerOptions{.address = "::1"}.problem(),
            "address: '::1' is not an IPv4 address");
  EXPECT_EQ(TrackerServerOptions{.max_queued_bytes = 0}.problem(),
            "max_queued_bytes: 0 leaves no room for a report");
  EXPECT_EQ(TrackerServerOptions{.max_clients = 0}.problem(),
            "max_clients: 0; every client would be refused");
  try {
    TrackerServer server({.port = 0, .max_clients = 0});
    ADD_FAILURE() << "a server for no client accepted";
  } catch (const std::invalid_argument& e) {
    EXPECT_STREQ(e.what(), "TrackerServerOptions::max_clients: 0; every client would be refused");
  }
}

}  // namespace
}  // namespace mocap::vrpn
