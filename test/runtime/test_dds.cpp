// DDS between processes: rediscovery, reliability (also with every core busy and with a slow
// subscriber), zero-copy kept beside remote subscribers, late joiners of latched topics, and
// the command-line tools.
#include <gtest/gtest.h>

#include <signal.h>

#include <filesystem>
#include <memory>
#include <set>

#include <fmt/format.h>

#include "test/test_support.hpp"

namespace mocap {
namespace {

std::map<std::string, std::string> environment(int slot) {
  return {{"MOCAP_DOMAIN_ID", std::to_string(test::test_domain(slot))},
          {"MOCAP_PLUGIN_PATH", test::test_plugin_dir().string()}};
}

// The Fast DDS shared-memory ports process `pid` reads from: the lock files it holds open.
std::set<std::string> shared_memory_ports(int pid) {
  std::set<std::string> ports;
  std::error_code error;
  for (const auto& fd :
       std::filesystem::directory_iterator(fmt::format("/proc/{}/fd", pid), error)) {
    std::string target = std::filesystem::read_symlink(fd.path(), error).filename().string();
    if (target.rfind("fastrtps_port", 0) == 0 && target.size() > 3 &&
        target.compare(target.size() - 3, 3, "_el") == 0) {
      ports.insert(target);
    }
  }
  return ports;
}

std::string launcher() { return (test::bin_dir() / "mocap_launch").string(); }
std::string topic_tool() { return (test::bin_dir() / "mocap_topic").string(); }

// One group holding sequence_source or sequence_sink (`role`), named after its role.
std::string one_component_yaml(const std::string& role, const std::string& parameters,
                               const std::string& qos) {
  return fmt::format(R"(groups:
  - name: {0}
    components:
      - plugin: sequence_{0}
        name: {0}
        parameters: {{{1}}}
        qos: {{/test/sequence: {2}}}
)",
                     role, parameters, qos);
}

std::string source_yaml(const std::string& parameters, const std::string& qos = "reliable") {
  return one_component_yaml("source", parameters, qos);
}

std::string sink_yaml(const std::string& parameters, const std::string& qos = "reliable") {
  return one_component_yaml("sink", parameters, qos);
}

// The machine a reliable stream must not lose samples on: quiet, with every core busy with
// other processes, with a subscriber that takes 2 ms over each message (far slower than its
// publisher, which must then wait for it), both at once, or with a subscriber that stalls for
// two seconds now and then.
constexpr int kSlowWorkMs = 2;
enum class Load {
  Quiet,
  BusyCores,
  SlowSubscriber,
  BusyCoresAndSlowSubscriber,
  StallingSubscriber
};

std::string load_name(const ::testing::TestParamInfo<Load>& info) {
  switch (info.param) {
    case Load::Quiet:
      return "Quiet";
    case Load::BusyCores:
      return "BusyCores";
    case Load::SlowSubscriber:
      return "SlowSubscriber";
    case Load::BusyCoresAndSlowSubscriber:
      return "BusyCoresAndSlowSubscriber";
    case Load::StallingSubscriber:
      return "StallingSubscriber";
  }
  return "?";
}

class ReliableUnderLoad : public ::testing::TestWithParam<Load> {
 protected:
  void SetUp() override {
    if (GetParam() == Load::BusyCores || GetParam() == Load::BusyCoresAndSlowSubscriber) {
      busy_ = std::make_unique<test::BusyCores>();
    }
  }
  void TearDown() override { busy_.reset(); }

  bool slow() const {
    return GetParam() == Load::SlowSubscriber || GetParam() == Load::BusyCoresAndSlowSubscriber;
  }

  // The DDS domain of this test under this load: `slot` to `slot` + 4.
  std::map<std::string, std::string> env(int slot) const {
    return environment(slot + static_cast<int>(GetParam()));
  }
  // The sink's parameters under this load.
  std::string sink(const std::string& parameters) const {
    if (slow()) return parameters + fmt::format(", work_s: {}", kSlowWorkMs / 1000.0);
    if (GetParam() == Load::StallingSubscriber) {
      return parameters + ", stall_every: 2500, stall_s: 2.0";
    }
    return parameters;
  }

 private:
  std::unique_ptr<test::BusyCores> busy_;
};

INSTANTIATE_TEST_SUITE_P(Dds, ReliableUnderLoad,
                         ::testing::Values(Load::Quiet, Load::BusyCores, Load::SlowSubscriber,
                                           Load::BusyCoresAndSlowSubscriber,
                                           Load::StallingSubscriber),
                         load_name);

TEST_P(ReliableUnderLoad, LosesNothingAcrossTenThousandMessages) {
  test::TempDir dir;
  test::write_file(dir / "graph.yaml",
                   fmt::format(R"(groups:
  - name: source
    components:
      - plugin: sequence_source
        name: source
        parameters: {{count: 10000, batch: 200, period_s: 0.002, summary_file: "{}"}}
  - name: sink
    components:
      - plugin: sequence_sink
        name: sink
        parameters: {{{}}}
)",
                               (dir / "source.yaml").string(),
                               sink(fmt::format("expect: 10000, summary_file: \"{}\", "
                                                "timeout_s: 300",
                                                (dir / "summary.yaml").string()))));
  auto [code, output] = test::run_command({launcher(), (dir / "graph.yaml").string()}, env(21),
                                          std::chrono::seconds(400));
  ASSERT_EQ(code, 0) << output;
  auto summary = test::read_summary(dir / "summary.yaml");
  EXPECT_EQ(summary.at("received"), 10000);
  EXPECT_EQ(summary.at("first"), 0);
  EXPECT_EQ(summary.at("last"), 9999);
  EXPECT_EQ(summary.at("missing"), 0);
  EXPECT_EQ(summary.at("out_of_order"), 0);
  EXPECT_EQ(summary.at("corrupt"), 0);
  EXPECT_EQ(output.find("dropped"), std::string::npos) << output;
  auto source = test::read_summary(dir / "source.yaml");
  EXPECT_EQ(source.at("published"), 10000);
  EXPECT_EQ(source.at("dropped"), 0);
  if (slow()) {
    // 10,000 messages in about 0.2 s against 20 s of work: the publisher waited through most
    // of that work, and said so. How many samples waited is not asserted: it depends on the
    // implementation's window (Fast DDS lets 32 be unacknowledged, Cyclone DDS 500 kB and wakes
    // a waiting writer only when most are acknowledged) and on how the load batches the
    // acknowledgements (67 on a busy CI machine with Cyclone DDS, several hundred here).
    // Nor is most of the work: a fifth of it, as when it was 50 s (5 ms a message) and a busy
    // machine's scheduling took a larger share. A publisher that buffered instead of waiting
    // would block for none of it.
    std::printf("the publisher blocked %lld ms of the subscriber's %d ms of work\n",
                source.at("blocked_ms"), kSlowWorkMs * 10000);
    EXPECT_GT(source.at("waited"), 0);
    EXPECT_GT(source.at("blocked_ms"), kSlowWorkMs * 10000 / 5);
    EXPECT_NE(output.find("publisher waits for DDS subscriber(s) in 'sink'"), std::string::npos)
        << output;
  }
  if (GetParam() == Load::StallingSubscriber) {
    // Through most of a stall: the publisher fills the subscriber's history and the
    // implementation's window first (Cyclone DDS's 500 kB take a while on a busy machine).
    EXPECT_GT(source.at("longest_wait_ms"), 500);
  }
}

TEST_P(ReliableUnderLoad, ARestartedSubscriberProcessReceivesAgain) {
  test::TempDir dir;
  auto environment = env(31);
  // 1000 messages a second: more than a slow subscriber takes, so the publisher waits for it
  // when the first subscriber is killed.
  test::write_file(dir / "source.yaml",
                   source_yaml("count: 0, batch: 10, period_s: 0.01, subscribers: 0"));
  test::write_file(dir / "sink.yaml",
                   sink_yaml(sink(fmt::format("expect: 0, log_every: 20, timeout_s: 300, "
                                              "summary_file: \"{}\"",
                                              (dir / "summary.yaml").string()))));
  test::ChildProcess source({launcher(), (dir / "source.yaml").string()}, environment,
                            dir / "source.log");

  test::ChildProcess first({launcher(), (dir / "sink.yaml").string()}, environment,
                           dir / "first.log");
  ASSERT_TRUE(first.wait_for_output("received 200", std::chrono::seconds(60))) << first.output();
  std::set<std::string> first_ports = shared_memory_ports(first.pid());
  EXPECT_EQ(first_ports.size(), test::dds_implementation() == "fastdds" ? 2u : 0u);
  first.signal(SIGKILL);  // no goodbye to the publisher
  ASSERT_EQ(first.wait(std::chrono::seconds(10)), 128 + SIGKILL);

  test::ChildProcess second({launcher(), (dir / "sink.yaml").string()}, environment,
                            dir / "second.log");
  // The publisher may still write to the shared memory of the killed process's ports, and
  // would never reach a process that took them (fastdds_shared_memory.hpp).
  ASSERT_TRUE(second.wait_for_output("running sink", std::chrono::seconds(60))) << second.output();
  for (const std::string& port : shared_memory_ports(second.pid())) {
    EXPECT_EQ(first_ports.count(port), 0u) << port << " again";
  }
  EXPECT_TRUE(second.wait_for_output("received 200", std::chrono::seconds(60)))
      << second.output() << source.output();
  second.signal(SIGTERM);
  EXPECT_EQ(second.wait(std::chrono::seconds(30)), 0) << second.output();
  // From its first message on, the second subscriber got every one, once, in order.
  auto summary = test::read_summary(dir / "summary.yaml");
  EXPECT_GE(summary.at("received"), 200);
  EXPECT_EQ(summary.at("last") - summary.at("first") + 1, summary.at("received"));
  EXPECT_EQ(summary.at("missing"), 0);
  EXPECT_EQ(summary.at("out_of_order"), 0);
  EXPECT_EQ(summary.at("corrupt"), 0);
  source.signal(SIGTERM);
  EXPECT_EQ(source.wait(std::chrono::seconds(30)), 0) << source.output();
  // Nothing dropped while it ran. Stopping, it may drop the sample it was writing for a
  // subscriber that has left but not yet been seen to leave (its DDS goodbye still on the way):
  // no process could have received that one.
  const std::string output = source.output();
  EXPECT_EQ(output.substr(0, output.find("shutting down on signal")).find("dropped"),
            std::string::npos)
      << output;
}

TEST_P(ReliableUnderLoad, ALatchedSampleReachesAProcessStartedLater) {
  test::TempDir dir;
  auto environment = env(50);
  test::write_file(dir / "source.yaml", source_yaml("count: 1, subscribers: 0", "latched"));
  test::write_file(
      dir / "sink.yaml",
      sink_yaml(sink(fmt::format("expect: 1, summary_file: \"{}\"", (dir / "summary").string())),
                "latched"));
  test::ChildProcess source({launcher(), (dir / "source.yaml").string()}, environment,
                            dir / "source.log");
  ASSERT_TRUE(source.wait_for_output("published 1 messages", std::chrono::seconds(30)));
  auto [code, output] = test::run_command({launcher(), (dir / "sink.yaml").string()}, environment);
  EXPECT_EQ(code, 0) << output;
  auto summary = test::read_summary(dir / "summary");
  EXPECT_EQ(summary.at("received"), 1);
  EXPECT_EQ(summary.at("first"), 0);
  source.signal(SIGTERM);
}

// A reliable publisher is transient_local on the wire (to_writer_qos says why) and so keeps a
// history; a latched subscriber in another process still takes nothing from it, as in one
// process, and says why.
TEST(Dds, ALatchedSubscriberTakesNothingFromAReliablePublisher) {
  test::TempDir dir;
  auto env = environment(13);
  test::write_file(dir / "source.yaml",
                   source_yaml("count: 0, batch: 10, period_s: 0.01, subscribers: 1"));
  test::write_file(dir / "volatile.yaml", sink_yaml("expect: 0, log_every: 100, timeout_s: 300"));
  test::write_file(dir / "latched.yaml",
                   sink_yaml(fmt::format("expect: 0, timeout_s: 300, summary_file: \"{}\"",
                                         (dir / "latched.summary").string()),
                             "latched"));
  test::ChildProcess source({launcher(), (dir / "source.yaml").string()}, env, dir / "source.log");
  test::ChildProcess reader({launcher(), (dir / "volatile.yaml").string()}, env,
                            dir / "volatile.log");
  ASSERT_TRUE(reader.wait_for_output("received 100", std::chrono::seconds(60)))
      << reader.output() << source.output();
  test::ChildProcess latched({launcher(), (dir / "latched.yaml").string()}, env,
                             dir / "latched.log");
  EXPECT_TRUE(latched.wait_for_output(
      "/test/sequence: not connected to the publisher in 'source': the subscriber requests "
      "transient_local durability but the publisher is volatile",
      std::chrono::seconds(60)))
      << latched.output();
  // Live samples keep arriving at the volatile subscriber, and not at the latched one.
  int logged = 0;
  while (reader.output().find(fmt::format("received {}\n", logged + 100)) != std::string::npos) {
    logged += 100;
  }
  EXPECT_TRUE(
      reader.wait_for_output(fmt::format("received {}\n", logged + 300), std::chrono::seconds(60)))
      << reader.output();
  latched.signal(SIGTERM);
  ASSERT_EQ(latched.wait(std::chrono::seconds(30)), 0) << latched.output();
  EXPECT_EQ(test::read_summary(dir / "latched.summary").at("received"), 0) << latched.output();
}

// A publisher whose process ends right after its last sample still delivers every one: the
// writer waits for its subscribers' acknowledgements before it goes. Here the subscriber is
// 1000 samples behind when the publisher is done.
TEST(Dds, APublisherThatStopsDeliversItsLastSamples) {
  test::TempDir dir;
  auto env = environment(11);
  test::write_file(dir / "source.yaml", source_yaml("count: 2000, batch: 100, period_s: 0.001, "
                                                    "subscribers: 1, stop_when_done: true"));
  test::write_file(dir / "sink.yaml",
                   sink_yaml(fmt::format("expect: 2000, work_s: 0.001, timeout_s: 60, "
                                         "summary_file: \"{}\"",
                                         (dir / "summary.yaml").string())));
  test::ChildProcess sink({launcher(), (dir / "sink.yaml").string()}, env, dir / "sink.log");
  test::ChildProcess source({launcher(), (dir / "source.yaml").string()}, env, dir / "source.log");
  ASSERT_EQ(source.wait(std::chrono::seconds(60)), 0) << source.output();
  EXPECT_EQ(source.output().find("publisher closed before"), std::string::npos) << source.output();
  ASSERT_EQ(sink.wait(std::chrono::seconds(90)), 0) << sink.output();
  auto summary = test::read_summary(dir / "summary.yaml");
  EXPECT_EQ(summary.at("received"), 2000);
  EXPECT_EQ(summary.at("missing"), 0);
  EXPECT_EQ(summary.at("out_of_order"), 0);
}

// A publisher waiting for a slow subscriber in another process resumes as soon as that
// subscriber leaves, not after DDS's lease on it (5 s) runs out.
TEST(Dds, ASubscriberThatLeavesReleasesAWaitingPublisherAtOnce) {
  test::TempDir dir;
  auto env = environment(19);
  test::write_file(dir / "source.yaml",
                   source_yaml(fmt::format("count: 20000, batch: 20, period_s: 0.002, "
                                           "subscribers: 1, summary_file: \"{}\"",
                                           (dir / "source.summary").string())));
  test::write_file(dir / "slow.yaml",
                   sink_yaml("expect: 0, work_s: 0.005, log_every: 100, timeout_s: 300"));
  test::write_file(dir / "fast.yaml", sink_yaml(fmt::format("expect: 0, timeout_s: 300, "
                                                            "summary_file: \"{}\"",
                                                            (dir / "fast.summary").string())));
  test::ChildProcess slow({launcher(), (dir / "slow.yaml").string()}, env, dir / "slow.log");
  test::ChildProcess source({launcher(), (dir / "source.yaml").string()}, env, dir / "source.log");
  ASSERT_TRUE(source.wait_for_output("publisher waits for DDS subscriber(s) in 'sink'",
                                     std::chrono::seconds(60)))
      << source.output() << slow.output();
  test::ChildProcess fast({launcher(), (dir / "fast.yaml").string()}, env, dir / "fast.log");
  ASSERT_TRUE(slow.wait_for_output("received 300", std::chrono::seconds(60))) << slow.output();
  slow.signal(SIGTERM);  // a goodbye: its reader leaves the graph at once
  ASSERT_EQ(slow.wait(std::chrono::seconds(30)), 0) << slow.output();
  ASSERT_TRUE(source.wait_for_output("published 20000 messages", std::chrono::seconds(120)))
      << source.output();
  auto published = test::read_summary(dir / "source.summary");
  EXPECT_EQ(published.at("dropped"), 0);
  EXPECT_LT(published.at("longest_wait_ms"), 5000);
  fast.signal(SIGTERM);
  EXPECT_EQ(fast.wait(std::chrono::seconds(30)), 0) << fast.output();
  auto summary = test::read_summary(dir / "fast.summary");
  EXPECT_EQ(summary.at("last"), 19999);
  EXPECT_EQ(summary.at("last") - summary.at("first") + 1, summary.at("received"));
  EXPECT_EQ(summary.at("missing"), 0);
  source.signal(SIGTERM);
}

// A topic with subscribers in the publisher's process and in another: the local one still
// gets pointers, and gets each sample once (not again through DDS).
TEST(Dds, LocalDeliveryStaysZeroCopyAndSingleBesideARemoteSubscriber) {
  test::TempDir dir;
  auto env = environment(12);
  test::write_file(dir / "local.yaml", fmt::format(R"(groups:
  - name: local
    components:
      - plugin: sequence_source
        name: source
        parameters: {{count: 500, batch: 50, period_s: 0.01, subscribers: 2}}
      - plugin: sequence_sink
        name: local_sink
        parameters: {{expect: 500, summary_file: "{}", stop_when_done: false}}
)",
                                                   (dir / "local.yaml.summary").string()));
  test::write_file(dir / "remote.yaml",
                   sink_yaml(fmt::format("expect: 500, summary_file: \"{}\"",
                                         (dir / "remote.yaml.summary").string())));
  test::ChildProcess local({launcher(), (dir / "local.yaml").string()}, env, dir / "local.log");
  test::ChildProcess remote({launcher(), (dir / "remote.yaml").string()}, env, dir / "remote.log");
  ASSERT_EQ(remote.wait(std::chrono::seconds(90)), 0) << remote.output() << local.output();
  ASSERT_TRUE(local.wait_for_output("received 500 messages", std::chrono::seconds(30)))
      << local.output();
  // Anything the local sink would get twice would have arrived by now.
  std::this_thread::sleep_for(std::chrono::milliseconds(500));
  local.signal(SIGTERM);
  EXPECT_EQ(local.wait(std::chrono::seconds(30)), 0) << local.output();

  auto local_summary = test::read_summary(dir / "local.yaml.summary");
  EXPECT_EQ(local_summary.at("received"), 500);
  EXPECT_EQ(local_summary.at("same_object"), 500);
  EXPECT_EQ(local_summary.at("out_of_order"), 0);
  EXPECT_EQ(local.output().find("received 501"), std::string::npos);
  auto remote_summary = test::read_summary(dir / "remote.yaml.summary");
  EXPECT_EQ(remote_summary.at("received"), 500);
  EXPECT_EQ(remote_summary.at("missing"), 0);
  EXPECT_EQ(remote_summary.at("same_object"), 0);
}

TEST(Dds, TopicToolListsEchoesAndMeasures) {
  test::TempDir dir;
  auto env = environment(14);
  test::write_file(dir / "source.yaml",
                   source_yaml("count: 0, batch: 1, period_s: 0.01, subscribers: 0"));
  test::ChildProcess source({launcher(), (dir / "source.yaml").string()}, env, dir / "source.log");
  // The list waits 3 s for discovery: from a publisher that exists, not from one still starting
  // (a loaded machine can take that long to start a process).
  ASSERT_TRUE(source.wait_for_output("publishing", std::chrono::seconds(60))) << source.output();

  auto [list_code, list] = test::run_command({topic_tool(), "list", "--wait", "3"}, env);
  EXPECT_EQ(list_code, 0);
  EXPECT_NE(list.find("/test/sequence [mocap_msgs/msg/FiducialArray] 1 publisher(s)"),
            std::string::npos)
      << list;

  auto [echo_code, echo] =
      test::run_command({topic_tool(), "echo", "/test/sequence", "--count", "2"}, env);
  EXPECT_EQ(echo_code, 0) << echo;
  EXPECT_NE(echo.find("header:\n  stamp:\n    sec: "), std::string::npos) << echo;
  EXPECT_NE(echo.find("fiducials:\n  - x: "), std::string::npos) << echo;
  EXPECT_NE(echo.find("    uncertainty: 0.5\n"), std::string::npos) << echo;
  EXPECT_EQ(std::count(echo.begin(), echo.end(), '-') >= 2, true);

  auto [hz_code, hz] =
      test::run_command({topic_tool(), "hz", "/test/sequence", "--count", "2"}, env);
  EXPECT_EQ(hz_code, 0) << hz;
  EXPECT_NE(hz.find("average rate: "), std::string::npos) << hz;
  source.signal(SIGTERM);
}

TEST(Launcher, CheckReportsProblemsAndStartsNothing) {
  test::TempDir dir;
  test::write_file(dir / "bad.yaml", sink_yaml("expect: -1, colour: red"));
  auto [code, output] =
      test::run_command({launcher(), (dir / "bad.yaml").string(), "--check"}, environment(15));
  EXPECT_EQ(code, 1);
  EXPECT_NE(output.find("bad.yaml:6: component 'sink' (sequence_sink): unknown parameter 'colour'"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("bad.yaml: 2 problem(s); nothing was started"), std::string::npos)
      << output;
  // Without --check, the same file starts nothing either.
  auto [run_code, run_output] =
      test::run_command({launcher(), (dir / "bad.yaml").string()}, environment(15));
  EXPECT_EQ(run_code, 1);
  EXPECT_EQ(run_output.find("[INFO]"), std::string::npos) << run_output;

  test::write_file(dir / "good.yaml", sink_yaml("expect: 1"));
  auto [good_code, good] =
      test::run_command({launcher(), (dir / "good.yaml").string(), "--check"}, environment(15));
  EXPECT_EQ(good_code, 0) << good;
  EXPECT_NE(good.find("valid (1 group(s), 1 component(s))"), std::string::npos);

  auto [usage_code, usage] = test::run_command({launcher(), "--frobnicate"});
  EXPECT_EQ(usage_code, 2);
  EXPECT_NE(usage.find("unknown option --frobnicate"), std::string::npos);
}

TEST(Launcher, DescribeListsParametersAndTopics) {
  auto [code, output] =
      test::run_command({launcher(), "--describe", "sequence_sink"}, environment(16));
  EXPECT_EQ(code, 0) << output;
  EXPECT_NE(output.find("  expect: int >= 0 = 1000\n"), std::string::npos) << output;
  EXPECT_NE(output.find("subscribes /test/sequence [mocap_msgs/msg/FiducialArray] reliable"),
            std::string::npos)
      << output;
  auto [missing_code, missing] =
      test::run_command({launcher(), "--describe", "sequence_snk"}, environment(16));
  EXPECT_EQ(missing_code, 1);
  EXPECT_NE(missing.find("did you mean 'sequence_sink'?"), std::string::npos) << missing;
}

TEST(Launcher, CtrlCStopsEveryGroupCleanly) {
  test::TempDir dir;
  test::write_file(dir / "graph.yaml", R"(groups:
  - name: one
    components:
      - plugin: sequence_sink
        name: a
        parameters: {expect: 0}
  - name: two
    components:
      - plugin: sequence_source
        name: b
        parameters: {count: 0, subscribers: 0}
)");
  test::ChildProcess launch({launcher(), (dir / "graph.yaml").string()}, environment(18),
                            dir / "launch.log");
  ASSERT_TRUE(launch.wait_for_output("[two] ", std::chrono::seconds(30))) << launch.output();
  ASSERT_TRUE(launch.wait_for_output("[one] ", std::chrono::seconds(30))) << launch.output();
  launch.signal(SIGINT);
  EXPECT_EQ(launch.wait(std::chrono::seconds(30)), 0) << launch.output();
  EXPECT_NE(launch.output().find("[launch] stopping all groups"), std::string::npos);
  EXPECT_NE(launch.output().find("[one] [INFO]"), std::string::npos) << launch.output();
  EXPECT_NE(launch.output().find("[two] [INFO]"), std::string::npos) << launch.output();
}

// A group whose component cannot start stops the whole deployment, loudly, with its code.
TEST(Launcher, AGroupThatFailsToStartStopsTheOthers) {
  test::TempDir dir;
  test::write_file(dir / "graph.yaml", R"(groups:
  - name: healthy
    components:
      - plugin: sequence_sink
        name: sink
        parameters: {expect: 0}
  - name: broken
    components:
      - plugin: failing_start
        name: servo
)");
  auto [code, output] =
      test::run_command({launcher(), (dir / "graph.yaml").string()}, environment(17));
  EXPECT_EQ(code, 1) << output;
  EXPECT_NE(output.find("[broken] " + (dir / "graph.yaml").string() +
                        ":10: component 'servo' (failing_start) failed to start: cannot open "
                        "/dev/ttyUSB9"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("[launch] group 'broken' exited with code 1 while starting; stopping the "
                        "others"),
            std::string::npos)
      << output;
}

}  // namespace
}  // namespace mocap
