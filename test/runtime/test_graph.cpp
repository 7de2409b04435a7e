// One graph, run three ways with the same assertions on what arrives: in one process, in
// two processes over DDS, and on two "hosts" (network namespaces joined by a veth pair).
#include <gtest/gtest.h>

#include <fmt/format.h>

#include "test/test_support.hpp"

namespace mocap {
namespace {

constexpr int kCount = 2000;

// The graph: a numbered stream from `source` to `sink`, reliable.
std::string graph(const std::filesystem::path& summary, bool split, bool shared_memory = true) {
  std::string source = R"(      - plugin: sequence_source
        name: source
        parameters: {count: 2000, batch: 100, period_s: 0.01}
)";
  std::string sink = fmt::format(R"(      - plugin: sequence_sink
        name: sink
        parameters: {{expect: 2000, summary_file: "{}", timeout_s: 60}}
)",
                                 summary.string());
  std::string dds = fmt::format("dds: {{shared_memory: {}}}\n", shared_memory);
  if (!split) return dds + "groups:\n  - name: all\n    components:\n" + source + sink;
  return dds + "groups:\n  - name: source\n    components:\n" + source +
         "  - name: sink\n    components:\n" + sink;
}

std::map<std::string, std::string> environment(int slot) {
  return {{"MOCAP_DOMAIN_ID", std::to_string(test::test_domain(slot))},
          {"MOCAP_PLUGIN_PATH", test::test_plugin_dir().string()}};
}

std::string launcher() { return (test::bin_dir() / "mocap_launch").string(); }

// What must arrive, however the graph is deployed.
void expect_complete_stream(const std::map<std::string, long long>& summary) {
  EXPECT_EQ(summary.at("received"), kCount);
  EXPECT_EQ(summary.at("first"), 0);
  EXPECT_EQ(summary.at("last"), kCount - 1);
  EXPECT_EQ(summary.at("missing"), 0);
  EXPECT_EQ(summary.at("out_of_order"), 0);
  EXPECT_EQ(summary.at("corrupt"), 0);
}

TEST(Graph, OneProcessDeliversByPointer) {
  test::TempDir dir;
  test::write_file(dir / "graph.yaml", graph(dir / "summary.yaml", false));
  auto [code, output] =
      test::run_command({launcher(), (dir / "graph.yaml").string()}, environment(1));
  ASSERT_EQ(code, 0) << output;
  auto summary = test::read_summary(dir / "summary.yaml");
  expect_complete_stream(summary);
  EXPECT_EQ(summary.at("same_object"), kCount);  // the subscriber saw the publisher's pointers
}

TEST(Graph, TwoProcessesOverDds) {
  test::TempDir dir;
  test::write_file(dir / "graph.yaml", graph(dir / "summary.yaml", true));
  auto [code, output] =
      test::run_command({launcher(), (dir / "graph.yaml").string()}, environment(2));
  ASSERT_EQ(code, 0) << output;
  EXPECT_NE(output.find("[sink] "), std::string::npos) << output;  // the sink ran in its group
  EXPECT_NE(output.find("[source] "), std::string::npos) << output;
  expect_complete_stream(test::read_summary(dir / "summary.yaml"));
}

TEST(Graph, TwoHostsOverANetwork) {
  test::TwoHosts hosts;
  if (!hosts.error().empty()) GTEST_SKIP() << "cannot make network namespaces: " << hosts.error();
  test::TempDir dir;
  // No shared memory: the hosts share this machine's /dev/shm, and the test is about the
  // network path.
  test::write_file(dir / "graph.yaml", graph(dir / "summary.yaml", true, false));
  std::string file = (dir / "graph.yaml").string();
  long long received_before = hosts.bytes_received_by_a();
  test::ChildProcess sink(hosts.on_a({launcher(), file, "--group", "sink"}), environment(3),
                          dir / "sink.log");
  test::ChildProcess source(hosts.on_b({launcher(), file, "--group", "source"}), environment(3),
                            dir / "source.log");
  auto code = sink.wait(std::chrono::seconds(90));
  source.signal(SIGTERM);
  ASSERT_EQ(code, 0) << sink.output() << source.output();
  EXPECT_EQ(source.wait(std::chrono::seconds(30)), 0) << source.output();
  expect_complete_stream(test::read_summary(dir / "summary.yaml"));
  // The stream crossed the veth: at least its payload arrived on host A's link.
  EXPECT_GT(hosts.bytes_received_by_a() - received_before, kCount * 40);
}

// `timeout` stops a graph as many supervisors do (docker stop, process-group kills): SIGTERM to
// mocap_launch and, in the same instant, to its whole process group, the groups' processes
// included. That is one stop request: every group stops gracefully, the sink (in its own
// process) writes its summary, and the exit status is 0, not the forced exit's 130.
TEST(Graph, ASignalToTheWholeProcessGroupIsOneStopRequest) {
  test::TempDir dir;
  test::write_file(dir / "graph.yaml", fmt::format(R"(groups:
  - name: source
    components:
      - plugin: sequence_source
        name: source
        parameters: {{count: 0, batch: 10, period_s: 0.01}}
  - name: sink
    components:
      - plugin: sequence_sink
        name: sink
        parameters: {{expect: 1000000000, summary_file: "{}", timeout_s: 300}}
)",
                                                   (dir / "summary.yaml").string()));
  auto [code, output] = test::run_command({"timeout", "--preserve-status", "-s", "TERM", "6",
                                           launcher(), (dir / "graph.yaml").string()},
                                          environment(4), std::chrono::seconds(60));
  EXPECT_EQ(code, 0) << output;
  EXPECT_EQ(output.find("forcing the exit"), std::string::npos) << output;
  auto summary = test::read_summary(dir / "summary.yaml");
  EXPECT_GT(summary.at("received"), 0) << output;
  EXPECT_EQ(summary.at("missing"), 0);
}

}  // namespace
}  // namespace mocap
