// mocap_launch supervising its groups' processes: one that dies after it has started is
// started again while the others go on, and the restart is said on /alerts; one that keeps
// dying is given up on; a required one ends the deployment; one without respawn stays down.
// The processes are killed for real (SIGKILL), as a crash would end them.
#include <gtest/gtest.h>

#include <csignal>
#include <regex>
#include <string>
#include <thread>

#include "test/test_support.hpp"

namespace mocap {
namespace {

using std::chrono::seconds;

std::map<std::string, std::string> environment(int slot) {
  return {{"MOCAP_DOMAIN_ID", std::to_string(test::test_domain(slot))},
          {"MOCAP_PLUGIN_PATH", test::test_plugin_dir().string()}};
}

std::string launcher() { return (test::bin_dir() / "mocap_launch").string(); }

// A source and a sink in groups of their own; `sink_keys` go into the sink's group.
std::string two_groups(const std::string& sink_keys = "") {
  return R"(dds: {shared_memory: false}
groups:
  - name: source
    components:
      - plugin: sequence_source
        name: source
        parameters: {count: 0, period_s: 0.02, subscribers: 0}
        qos: {/test/sequence: {profile: reliable, max_blocking_s: 0.1}}
  - name: sink
)" + sink_keys +
         R"(    components:
      - plugin: sequence_sink
        name: sink
        parameters: {expect: 0}
)";
}

// The pid the launcher last started `group` with ("group 'sink' started (pid 123)").
int pid_of(const std::string& output, const std::string& group) {
  const std::regex started("\\[launch\\] group '" + group + "' started \\(pid (\\d+)\\)");
  int pid = -1;
  for (std::sregex_iterator it(output.begin(), output.end(), started), end; it != end; ++it) {
    pid = std::stoi((*it)[1]);
  }
  return pid;
}

size_t count_of(const std::string& text, const std::string& part) {
  size_t count = 0;
  for (size_t at = text.find(part); at != std::string::npos; at = text.find(part, at + 1)) ++count;
  return count;
}

// Until the launcher has said `times` times that `group` runs again.
void wait_until_running_again(test::ChildProcess& launch, const std::string& group, int times) {
  const auto give_up = std::chrono::steady_clock::now() + seconds(20);
  while (count_of(launch.output(), "group '" + group + "' is running again") <
         static_cast<size_t>(times)) {
    ASSERT_FALSE(launch.wait(seconds(0))) << launch.output();
    ASSERT_LT(std::chrono::steady_clock::now(), give_up) << launch.output();
    std::this_thread::sleep_for(std::chrono::milliseconds(50));
  }
}

// The group's process killed twice: each time started again, the source group untouched, the
// restarts on /alerts; the launcher ends with the duration, with code 0 (it rode through).
TEST(Launcher, AGroupThatDiesIsRestartedAndTheOthersGoOn) {
  test::TempDir dir;
  test::write_file(dir / "graph.yaml", two_groups());
  test::ChildProcess alerts(
      {(test::bin_dir() / "mocap_topic").string(), "echo", "/alerts", "--count", "2"},
      environment(32), dir / "alerts.log");
  test::ChildProcess launch({launcher(), (dir / "graph.yaml").string(), "--duration", "15"},
                            environment(32), dir / "launch.log");
  ASSERT_TRUE(launch.wait_for_output("[sink] [INFO]", seconds(30))) << launch.output();
  const int source_pid = pid_of(launch.output(), "source");
  for (int death = 1; death <= 2; ++death) {
    std::this_thread::sleep_for(seconds(1));
    const int sink_pid = pid_of(launch.output(), "sink");
    ASSERT_GT(sink_pid, 0) << launch.output();
    ASSERT_EQ(::kill(sink_pid, SIGKILL), 0);
    ASSERT_TRUE(
        launch.wait_for_output("restarting it in " + std::string(death == 1 ? "0.25" : "0.50") +
                                   " s (death " + std::to_string(death) + " of 5 within 60 s",
                               seconds(10)))
        << launch.output();
    wait_until_running_again(launch, "sink", death);
  }
  EXPECT_NE(launch.output().find("group 'sink' was killed by signal 9"), std::string::npos);
  EXPECT_EQ(pid_of(launch.output(), "source"), source_pid) << "the source was started again";
  EXPECT_EQ(launch.wait(seconds(40)), 0) << launch.output();
  EXPECT_EQ(count_of(launch.output(), "group 'sink' started"), 3u) << launch.output();
  EXPECT_EQ(count_of(launch.output(), "group 'source' started"), 1u) << launch.output();
  ASSERT_EQ(alerts.wait(seconds(10)), 0) << alerts.output();
  const std::string said = alerts.output();
  EXPECT_NE(said.find("source: \"launch\""), std::string::npos) << said;
  EXPECT_NE(said.find("restarting it in 0.25 s"), std::string::npos) << said;
  EXPECT_NE(said.find("restarting it in 0.50 s"), std::string::npos) << said;
}

// Killed each time it runs again: the fifth death within 60 s gives it up, the source goes on,
// and the launcher's exit code says a group failed for good (128 + 9).
TEST(Launcher, AGroupThatKeepsDyingIsGivenUpOn) {
  test::TempDir dir;
  test::write_file(dir / "graph.yaml", two_groups());
  test::ChildProcess launch({launcher(), (dir / "graph.yaml").string()}, environment(33),
                            dir / "launch.log");
  ASSERT_TRUE(launch.wait_for_output("[sink] [INFO]", seconds(30))) << launch.output();
  for (int death = 1; death <= 5; ++death) {
    if (death > 1) {
      ASSERT_TRUE(launch.wait_for_output("death " + std::to_string(death - 1) + " of 5 within 60 s",
                                         seconds(10)))
          << launch.output();
      wait_until_running_again(launch, "sink", death - 1);
    }
    ASSERT_EQ(::kill(pid_of(launch.output(), "sink"), SIGKILL), 0);
  }
  ASSERT_TRUE(launch.wait_for_output("it died 5 times within 60 s: given up, the others go on",
                                     seconds(10)))
      << launch.output();
  std::this_thread::sleep_for(seconds(1));
  EXPECT_FALSE(launch.wait(seconds(0))) << "the deployment ended with the given-up group\n"
                                        << launch.output();
  launch.signal(SIGINT);
  EXPECT_EQ(launch.wait(seconds(30)), 128 + SIGKILL) << launch.output();
  EXPECT_EQ(count_of(launch.output(), "group 'sink' started"), 5u) << launch.output();
}

// A required group's death ends the deployment, with its exit code.
TEST(Launcher, ARequiredGroupThatDiesEndsTheDeployment) {
  test::TempDir dir;
  test::write_file(dir / "graph.yaml", two_groups("    required: true\n"));
  test::ChildProcess launch({launcher(), (dir / "graph.yaml").string()}, environment(34),
                            dir / "launch.log");
  ASSERT_TRUE(launch.wait_for_output("[sink] [INFO]", seconds(30))) << launch.output();
  ASSERT_EQ(::kill(pid_of(launch.output(), "sink"), SIGKILL), 0);
  EXPECT_EQ(launch.wait(seconds(30)), 128 + SIGKILL) << launch.output();
  EXPECT_NE(launch.output().find("group 'sink' was killed by signal 9"), std::string::npos);
  EXPECT_NE(launch.output().find("it is required: stopping the others"), std::string::npos)
      << launch.output();
  EXPECT_EQ(count_of(launch.output(), "group 'sink' started"), 1u) << launch.output();
}

// `respawn: false`: the group stays down and the others go on.
TEST(Launcher, AGroupWithoutRespawnStaysDown) {
  test::TempDir dir;
  test::write_file(dir / "graph.yaml", two_groups("    respawn: false\n"));
  test::ChildProcess launch({launcher(), (dir / "graph.yaml").string()}, environment(35),
                            dir / "launch.log");
  ASSERT_TRUE(launch.wait_for_output("[sink] [INFO]", seconds(30))) << launch.output();
  ASSERT_EQ(::kill(pid_of(launch.output(), "sink"), SIGKILL), 0);
  ASSERT_TRUE(
      launch.wait_for_output("not restarted (respawn: false), the others go on", seconds(10)))
      << launch.output();
  std::this_thread::sleep_for(seconds(2));
  EXPECT_FALSE(launch.wait(seconds(0))) << launch.output();
  EXPECT_EQ(count_of(launch.output(), "group 'sink' started"), 1u) << launch.output();
  launch.signal(SIGINT);
  EXPECT_EQ(launch.wait(seconds(30)), 128 + SIGKILL) << launch.output();
}

}  // namespace
}  // namespace mocap
