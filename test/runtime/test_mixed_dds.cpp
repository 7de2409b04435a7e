// One graph on two DDS implementations: Fast DDS and Cyclone DDS participants exchange every
// message type both ways, byte for byte, and a deployment whose processes run on different
// implementations works as one, on one machine and across two network-namespace hosts.
#include <gtest/gtest.h>

#include <signal.h>
#include <unistd.h>

#include <algorithm>
#include <chrono>
#include <random>
#include <regex>
#include <sstream>
#include <thread>

#include <fmt/format.h>

#include <mocap/generated_message_types.hpp>

#include "dds/dds_transport.hpp"
#include "host/dds_implementations.hpp"
#include "messages/idl_schema.hpp"
#include "test/random_cdr.hpp"
#include "test/test_support.hpp"

namespace mocap {
namespace {

using std::chrono::seconds;

std::vector<uint8_t> serialize(const MessageType& type, const void* message) {
  std::vector<uint8_t> bytes(type.serialized_size(message), 0);
  bytes.resize(type.serialize(message, bytes));
  return bytes;
}

std::unique_ptr<DdsTransport> participant(const std::string& implementation, int slot) {
  DdsOptions options;
  options.implementation = implementation;
  options.domain_id = test::mixed_domain(slot);
  return make_dds_transport(options, implementation + "_participant");
}

// Every generated type from `from`'s participant to `to`'s: kept (transient-local, keep all)
// by the publisher so that the subscriber, created afterwards, gets all of them without
// waiting for discovery first. What arrives is what was sent, byte for byte.
void expect_every_type_crosses(const std::string& from, const std::string& to, int slot) {
  constexpr int kPerType = 5;
  auto publisher_side = participant(from, slot);
  auto subscriber_side = participant(to, slot);
  EXPECT_EQ(publisher_side->implementation(), from);
  EXPECT_EQ(subscriber_side->implementation(), to);
  Qos qos{Reliability::Reliable, Durability::TransientLocal, History::KeepAll, 100};
  std::mt19937 random(5);
  size_t types = 0;
  for (const MessageType* type : generated_message_types()) {
    ++types;
    IdlSchema schema;
    schema.parse(full_definition(*type));
    Endpoint endpoint{"/mixed/" + type->name(), type, qos, "test"};
    auto publisher = publisher_side->advertise(endpoint);
    std::vector<std::vector<uint8_t>> sent;
    for (int i = 0; i < kPerType; ++i) {
      std::vector<uint8_t> bytes = test::random_cdr(schema, type->name(), random);
      std::shared_ptr<void> message = type->create();
      type->deserialize(bytes, message.get());
      sent.push_back(serialize(*type, message.get()));
      publisher->publish(message, Clock::now());
    }
    auto subscription = subscriber_side->subscribe(endpoint, [](bool) {});
    std::vector<std::vector<uint8_t>> received;
    auto deadline = std::chrono::steady_clock::now() + seconds(20);
    while (received.size() < sent.size() && std::chrono::steady_clock::now() < deadline) {
      ReceivedMessage message;
      if (subscription->take(message)) {
        received.push_back(serialize(*type, message.message.get()));
      } else {
        std::this_thread::sleep_for(std::chrono::milliseconds(5));
      }
    }
    EXPECT_EQ(received, sent) << type->name() << " from " << from << " to " << to;
    // The publisher goes first, while its subscriber can still acknowledge: a publisher of one
    // implementation does not hear that a subscriber of the other left until its participant
    // does (launch_yaml/README.md), and would wait for it on closing.
    publisher.reset();
  }
  EXPECT_GE(types, 23u);
}

TEST(MixedDds, EveryMessageTypeCrossesFromFastDdsToCycloneDds) {
  expect_every_type_crosses("fastdds", "cyclonedds", 0);
}

TEST(MixedDds, EveryMessageTypeCrossesFromCycloneDdsToFastDds) {
  expect_every_type_crosses("cyclonedds", "fastdds", 1);
}

// The receive buffers (ss's "rb", which the kernel doubles) of this process's UDP sockets, as
// ss lists them.
std::vector<uint64_t> udp_receive_buffers() {
  auto [code, listing] = test::run_command({"ss", "-u", "-a", "-n", "-m", "-p"});
  EXPECT_EQ(code, 0) << listing;
  std::vector<uint64_t> buffers;
  const std::string ours = fmt::format("pid={},", getpid());
  std::istringstream lines(listing);
  std::string line;
  bool socket_is_ours = false;
  static const std::regex receive_buffer(R"(skmem:\(r\d+,rb(\d+),)");
  while (std::getline(lines, line)) {
    std::smatch match;
    if (std::regex_search(line, match, receive_buffer)) {
      if (socket_is_ours) buffers.push_back(std::stoull(match[1]));
      socket_is_ours = false;
    } else if (!line.empty() && line[0] != ' ' && line[0] != '\t') {
      socket_is_ours = line.find(ours) != std::string::npos;
    }
  }
  return buffers;
}

// Both implementations' sockets ask for kUdpSocketBufferBytes (as much as net.core.rmem_max
// lets them have): a camera image arrives whole, without repairs (dds_transport.hpp).
TEST(MixedDds, BothImplementationsReceiveUdpIntoLargeBuffers) {
  uint64_t rmem_max = 0;
  std::istringstream(test::read_file("/proc/sys/net/core/rmem_max")) >> rmem_max;
  const uint64_t expected = std::min<uint64_t>(kUdpSocketBufferBytes, rmem_max);
  for (const std::string implementation : {"fastdds", "cyclonedds"}) {
    const std::vector<uint64_t> before = udp_receive_buffers();
    auto transport = participant(implementation, 7);
    const std::vector<uint64_t> after = udp_receive_buffers();
    ASSERT_GT(after.size(), before.size()) << implementation << ": no UDP socket seen";
    EXPECT_GE(*std::max_element(after.begin(), after.end()), expected) << implementation;
  }
}

TEST(MixedDds, ASocketBufferCapIsSaidWithTheCommandThatLiftsIt) {
  test::TempDir dir;
  test::write_file(dir / "rmem_max", "212992\n");
  test::write_file(dir / "wmem_max", "4194304\n");
  EXPECT_EQ(udp_buffer_problem(dir.path()),
            "net.core.rmem_max is 212992 bytes: UDP socket buffers are capped there, and large "
            "samples (camera images) between hosts wait for repairs; to lift the cap: sysctl -w "
            "net.core.rmem_max=4194304 net.core.wmem_max=4194304");
  test::write_file(dir / "rmem_max", "8388608\n");
  EXPECT_EQ(udp_buffer_problem(dir.path()), std::nullopt);
  EXPECT_EQ(udp_buffer_problem(dir / "absent"), std::nullopt);  // no /proc: nothing to say
}

// Discovery across implementations: each lists the other's endpoints with their QoS and names.
TEST(MixedDds, EachImplementationDiscoversTheOthersEndpoints) {
  auto fast = participant("fastdds", 2);
  auto cyclone = participant("cyclonedds", 2);
  const MessageType& type = *find_message_type("mocap_msgs/msg/FiducialArray");
  auto fast_writer = fast->advertise({"/mixed/fast", &type, Qos::latched(), "test"});
  auto cyclone_writer = cyclone->advertise({"/mixed/cyclone", &type, Qos::reliable(), "test"});
  // An endpoint may be seen before its participant's name (then named by its GUID prefix).
  auto find = [](const DdsTransport& transport, const std::string& topic,
                 const std::string& participant) {
    DiscoveredEndpoint seen;
    auto deadline = std::chrono::steady_clock::now() + seconds(20);
    while (std::chrono::steady_clock::now() < deadline) {
      for (const DiscoveredEndpoint& endpoint : transport.discovered_endpoints()) {
        if (endpoint.topic != topic || !endpoint.is_publisher) continue;
        seen = endpoint;
        if (endpoint.participant == participant) return seen;
      }
      std::this_thread::sleep_for(std::chrono::milliseconds(20));
    }
    return seen;
  };
  DiscoveredEndpoint seen_by_cyclone = find(*cyclone, "/mixed/fast", "fastdds_participant");
  EXPECT_EQ(seen_by_cyclone.type, "mocap_msgs::msg::dds_::FiducialArray_");
  EXPECT_EQ(seen_by_cyclone.participant, "fastdds_participant");
  EXPECT_EQ(seen_by_cyclone.qos.durability, Durability::TransientLocal);
  DiscoveredEndpoint seen_by_fast = find(*fast, "/mixed/cyclone", "cyclonedds_participant");
  EXPECT_EQ(seen_by_fast.type, "mocap_msgs::msg::dds_::FiducialArray_");
  EXPECT_EQ(seen_by_fast.participant, "cyclonedds_participant");
  EXPECT_EQ(seen_by_fast.qos.reliability, Reliability::Reliable);
  // A reliable publisher is volatile whatever the wire says (dds_options.hpp).
  EXPECT_EQ(seen_by_fast.qos.durability, Durability::Volatile);
}

std::string launcher() { return (test::bin_dir() / "mocap_launch").string(); }

// A peer of the other implementation whose QoS cannot match: nothing connects, and
// `mocap_topic list`, on either implementation, names the pair and why.
TEST(MixedDds, TopicListNamesPairsThatCannotConnect) {
  auto fast = participant("fastdds", 8);
  auto cyclone = participant("cyclonedds", 8);
  const MessageType& type = *find_message_type("mocap_msgs/msg/FiducialArray");
  auto best_effort = fast->advertise({"/mixed/best_effort", &type, Qos::sensor_data(), "test"});
  auto wants_reliable =
      cyclone->subscribe({"/mixed/best_effort", &type, Qos::reliable(), "test"}, [](bool) {});
  auto volatile_writer = cyclone->advertise({"/mixed/volatile", &type, Qos::reliable(), "test"});
  auto wants_latched =
      fast->subscribe({"/mixed/volatile", &type, Qos::latched(), "test"}, [](bool) {});
  auto fine = fast->advertise({"/mixed/fine", &type, Qos::reliable(), "test"});
  auto fine_reader =
      cyclone->subscribe({"/mixed/fine", &type, Qos::reliable(), "test"}, [](bool) {});
  for (const char* implementation : {"fastdds", "cyclonedds"}) {
    SCOPED_TRACE(implementation);
    auto [code, output] =
        test::run_command({(test::bin_dir() / "mocap_topic").string(), "list", "--wait", "3"},
                          {{"MOCAP_DOMAIN_ID", std::to_string(test::mixed_domain(8))},
                           {"MOCAP_DDS_IMPLEMENTATION", implementation}});
    ASSERT_EQ(code, 0) << output;
    EXPECT_NE(output.find("/mixed/best_effort [mocap_msgs/msg/FiducialArray] 1 publisher(s), 1 "
                          "subscriber(s), 1 incompatible pair(s)\n  incompatible: publisher of "
                          "'fastdds_participant' -> subscriber of 'cyclonedds_participant': the "
                          "subscriber requests reliable delivery but the publisher offers "
                          "best_effort\n"),
              std::string::npos)
        << output;
    EXPECT_NE(output.find("/mixed/volatile [mocap_msgs/msg/FiducialArray] 1 publisher(s), 1 "
                          "subscriber(s), 1 incompatible pair(s)\n  incompatible: publisher of "
                          "'cyclonedds_participant' -> subscriber of 'fastdds_participant': the "
                          "subscriber requests transient_local durability but the publisher is "
                          "volatile\n"),
              std::string::npos)
        << output;
    EXPECT_NE(output.find("/mixed/fine [mocap_msgs/msg/FiducialArray] 1 publisher(s), 1 "
                          "subscriber(s)\n"),
              std::string::npos)
        << output;
  }
  EXPECT_EQ(best_effort->matched_subscribers(), 0u);
  // (The volatile writer is matched on the wire, transient local there, but the latched
  // subscriber takes nothing from it: dds_options.hpp.)
  EXPECT_EQ(fine->matched_subscribers(), 1u);
  fine.reset();
}

std::map<std::string, std::string> environment(int slot, const std::string& implementation) {
  return {{"MOCAP_DOMAIN_ID", std::to_string(test::mixed_domain(slot))},
          {"MOCAP_BIN_DIR", test::bin_dir().string()},
          {"MOCAP_PLUGIN_PATH", test::test_plugin_dir().string()},
          {"MOCAP_DDS_IMPLEMENTATION", implementation}};
}

// The tracking deployment of launch_yaml/distributed/tracking.yaml with its camera and robot
// on one implementation and its pose computation and observer on the other: poses are made
// from the camera's fiducials and reach the observer, across implementations both ways.
class MixedTracking : public ::testing::TestWithParam<bool> {};

TEST_P(MixedTracking, PosesCrossImplementationsBothWays) {
  bool sensor_on_fastdds = GetParam();
  std::string sensor_side = sensor_on_fastdds ? "fastdds" : "cyclonedds";
  std::string compute_side = sensor_on_fastdds ? "cyclonedds" : "fastdds";
  int slot = sensor_on_fastdds ? 3 : 4;
  test::TempDir dir;
  std::string file = (test::source_dir() / "launch_yaml/distributed/tracking.yaml").string();
  std::string servos = (dir / "servos").string();
  std::vector<std::string> set = {"--set",      "servos.device_link=" + servos,
                                  "--set",      "turret.port=" + servos,
                                  "--duration", "90"};
  auto group = [&](const std::string& name, const std::string& implementation) {
    std::vector<std::string> command = {launcher(), file, "--group", name};
    command.insert(command.end(), set.begin(), set.end());
    return std::make_unique<test::ChildProcess>(command, environment(slot, implementation),
                                                dir / (name + ".log"));
  };
  auto robot = group("robot", sensor_side);
  auto sensor = group("sensor", sensor_side);
  auto compute = group("compute", compute_side);
  auto observer = group("observer", compute_side);
  auto [code, output] = test::run_command(
      {(test::source_dir() / "scripts/scenario.sh").string(), "check", "--timeout", "45"},
      environment(slot, compute_side), seconds(90));
  EXPECT_EQ(code, 0) << output << compute->output() << sensor->output();
  EXPECT_NE(output.find("check: PASS 30 of 30 pose arrays with poses"), std::string::npos)
      << output;
  EXPECT_NE(sensor->output().find(sensor_side + " DDS domain"), std::string::npos)
      << sensor->output();
  EXPECT_NE(compute->output().find(compute_side + " DDS domain"), std::string::npos)
      << compute->output();
  for (auto* process : {observer.get(), compute.get(), sensor.get(), robot.get()}) {
    process->signal(SIGTERM);
    EXPECT_EQ(process->wait(seconds(30)), 0) << process->output();
  }
}

INSTANTIATE_TEST_SUITE_P(MixedDds, MixedTracking, ::testing::Bool(),
                         [](const ::testing::TestParamInfo<bool>& info) {
                           return info.param ? std::string("CameraOnFastDds")
                                             : std::string("CameraOnCycloneDds");
                         });

// A numbered stream between two hosts (network namespaces joined by a veth pair), the
// publisher on one implementation and the subscriber on the other: all arrives, in order.
TEST(MixedDds, TwoHostsOnDifferentImplementations) {
  test::TwoHosts hosts;
  if (!hosts.error().empty()) GTEST_SKIP() << "cannot make network namespaces: " << hosts.error();
  for (bool source_on_fastdds : {true, false}) {
    test::TempDir dir;
    test::write_file(dir / "graph.yaml", fmt::format(R"(dds: {{shared_memory: false}}
groups:
  - name: source
    dds: {{implementation: {}}}
    components:
      - plugin: sequence_source
        name: source
        parameters: {{count: 2000, batch: 100, period_s: 0.01}}
  - name: sink
    dds: {{implementation: {}}}
    components:
      - plugin: sequence_sink
        name: sink
        parameters: {{expect: 0, summary_file: "{}", timeout_s: 60, finish_at: 1999}}
)",
                                                     source_on_fastdds ? "fastdds" : "cyclonedds",
                                                     source_on_fastdds ? "cyclonedds" : "fastdds",
                                                     (dir / "summary.yaml").string()));
    std::string file = (dir / "graph.yaml").string();
    int slot = source_on_fastdds ? 5 : 6;
    test::ChildProcess sink(hosts.on_a({launcher(), file, "--group", "sink"}),
                            environment(slot, ""), dir / "sink.log");
    test::ChildProcess source(hosts.on_b({launcher(), file, "--group", "source"}),
                              environment(slot, ""), dir / "source.log");
    auto code = sink.wait(seconds(90));
    source.signal(SIGTERM);
    ASSERT_EQ(code, 0) << sink.output() << source.output();
    EXPECT_EQ(source.wait(seconds(30)), 0) << source.output();
    // From its first sample on, the subscriber got every one, once, in order. (A Cyclone DDS
    // subscriber starts at the newest sample of a Fast DDS publisher it discovers after that
    // publisher discovered it, so the very first ones may be missed: launch_yaml/README.md.)
    auto summary = test::read_summary(dir / "summary.yaml");
    EXPECT_EQ(summary.at("last"), 1999);
    EXPECT_EQ(summary.at("last") - summary.at("first") + 1, summary.at("received"));
    if (!source_on_fastdds) {
      EXPECT_EQ(summary.at("first"), 0);
    }
    EXPECT_EQ(summary.at("missing"), 0);
    EXPECT_EQ(summary.at("out_of_order"), 0);
    EXPECT_NE(
        sink.output().find(source_on_fastdds ? "cyclonedds DDS domain" : "fastdds DDS domain"),
        std::string::npos)
        << sink.output();
  }
}

}  // namespace
}  // namespace mocap
