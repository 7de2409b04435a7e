// mocap_topic doctor against graphs broken on purpose, one way per test, each a real graph of
// mocap_launch processes (the test plugins' numbered stream) on a DDS domain of its own: the
// doctor names the cause in one line with what to do, and says "all well" on a graph that works.
#include <gtest/gtest.h>

#include <fmt/format.h>

#include <cstdio>
#include <map>
#include <memory>
#include <regex>
#include <string>
#include <vector>

#include "test/test_support.hpp"

namespace mocap {
namespace {

constexpr const char* kSource = R"(
      - plugin: sequence_source
        name: source
        parameters: {count: 0, period_s: 0.05, batch: 1, subscribers: 0}
)";
constexpr const char* kSink = R"(
      - plugin: sequence_sink
        name: sink
        parameters: {expect: 0, timeout_s: 600, log_every: 20}
)";

class Doctor : public ::testing::Test {
 protected:
  // A launch file of `groups` (name -> its components' YAML).
  std::filesystem::path launch_file(const std::string& name,
                                    const std::vector<std::pair<std::string, std::string>>& groups,
                                    const std::string& dds = "") {
    std::string yaml = dds.empty() ? "" : "dds: " + dds + "\n";
    yaml += "groups:\n";
    for (const auto& [group, components] : groups) {
      yaml += fmt::format("  - name: {}\n    components:{}", group, components);
    }
    const auto path = dir_ / name;
    test::write_file(path, yaml);
    return path;
  }

  std::map<std::string, std::string> environment(int domain) const {
    return {{"MOCAP_DOMAIN_ID", std::to_string(domain)},
            {"MOCAP_PLUGIN_PATH", test::test_plugin_dir().string()}};
  }

  // Runs `file` (or one of its groups), and waits until its processes run.
  test::ChildProcess& start(const std::filesystem::path& file, int domain,
                            std::vector<std::string> more = {},
                            std::map<std::string, std::string> extra_environment = {}) {
    std::vector<std::string> argv = {(test::bin_dir() / "mocap_launch").string(), file.string()};
    argv.insert(argv.end(), more.begin(), more.end());
    std::map<std::string, std::string> env = environment(domain);
    env.insert(extra_environment.begin(), extra_environment.end());
    graphs_.push_back(std::make_unique<test::ChildProcess>(
        argv, env, dir_ / fmt::format("graph{}.log", graphs_.size())));
    EXPECT_TRUE(graphs_.back()->wait_for_output("running", std::chrono::seconds(30)))
        << graphs_.back()->output();
    return *graphs_.back();
  }

  // The doctor's exit code and output, looking at `domain`.
  std::pair<int, std::string> doctor(int domain, std::vector<std::string> args = {}) {
    std::vector<std::string> argv = {(test::bin_dir() / "mocap_topic").string(), "doctor",
                                     "--seconds", "4"};
    argv.insert(argv.end(), args.begin(), args.end());
    auto result = test::run_command(argv, environment(domain), std::chrono::seconds(60));
    std::printf("%s", result.second.c_str());
    return result;
  }

  test::TempDir dir_;
  std::vector<std::unique_ptr<test::ChildProcess>> graphs_;
};

int count_problems(const std::string& output) {
  int problems = 0;
  for (size_t at = output.find("problem:"); at != std::string::npos;
       at = output.find("problem:", at + 1)) {
    ++problems;
  }
  return problems;
}

TEST_F(Doctor, SaysAllWellOnAGraphThatWorks) {
  const int domain = test::test_domain(43);
  const auto file = launch_file("graph.yaml", {{"source", kSource}, {"sink", kSink}});
  start(file, domain).wait_for_output("received 20", std::chrono::seconds(30));
  const auto [code, output] = doctor(domain, {file.string()});
  EXPECT_EQ(code, 0) << output;
  EXPECT_NE(output.find("all well: "), std::string::npos) << output;
  EXPECT_NE(output.find("every group of " + file.string() + " running"), std::string::npos);
  EXPECT_NE(output.find("source on "), std::string::npos) << output;
  EXPECT_NE(output.find("sink on "), std::string::npos) << output;
  EXPECT_EQ(count_problems(output), 0) << output;
}

TEST_F(Doctor, NamesAGroupThatIsNotRunning) {
  const int domain = test::test_domain(44);
  const auto file = launch_file("graph.yaml", {{"source", kSource}, {"sink", kSink}});
  start(file, domain, {"--group", "source"});
  const auto [code, output] = doctor(domain, {file.string()});
  EXPECT_EQ(code, 1) << output;
  EXPECT_NE(output.find(fmt::format("problem: group 'sink' of {} is not running", file.string())),
            std::string::npos)
      << output;
  EXPECT_NE(output.find(fmt::format("mocap_launch {} --group sink", file.string())),
            std::string::npos)
      << output;
}

TEST_F(Doctor, NamesATopicNobodyPublishesAndTheOneMeant) {
  const int domain = test::test_domain(45);
  const std::string misspelt =
      std::string(kSink) + "        remap: {/test/sequence: /test/sequenc}\n";
  const auto file = launch_file("graph.yaml", {{"source", kSource}, {"sink", misspelt}});
  start(file, domain);
  const auto [code, output] = doctor(domain, {file.string()});
  EXPECT_EQ(code, 1) << output;
  EXPECT_NE(output.find("problem: nobody publishes /test/sequenc, which sink (sink) read(s)"),
            std::string::npos)
      << output;
  EXPECT_NE(output.find("did you mean /test/sequence"), std::string::npos) << output;
}

TEST_F(Doctor, NamesTypesThatDiffer) {
  const int domain = test::test_domain(46);
  start(launch_file("source.yaml", {{"source", kSource}}), domain);
  start(launch_file("images.yaml", {{"images", R"(
      - plugin: image_sink
        name: images
)"}}),
        domain);
  const auto [code, output] = doctor(domain);
  EXPECT_EQ(code, 1) << output;
  EXPECT_NE(output.find("problem: /test/sequence is published as mocap_msgs/msg/FiducialArray by "
                        "source and read as sensor_msgs/msg/Image by images: they never connect"),
            std::string::npos)
      << output;
}

TEST_F(Doctor, NamesQosThatCannotMatch) {
  const int domain = test::test_domain(47);
  const std::string best_effort =
      std::string(kSource) + "        qos: {/test/sequence: {profile: sensor_data}}\n";
  start(launch_file("source.yaml", {{"source", best_effort}}), domain);
  start(launch_file("sink.yaml", {{"sink", kSink}}), domain);
  const auto [code, output] = doctor(domain);
  EXPECT_EQ(code, 1) << output;
  EXPECT_NE(output.find("problem: /test/sequence: source's publisher and sink's subscriber cannot "
                        "match (the subscriber requests reliable delivery but the publisher "
                        "offers best_effort)"),
            std::string::npos)
      << output;
}

TEST_F(Doctor, FindsTheGraphOnAnotherDomain) {
  const int domain = test::test_domain(48);
  const int other = test::test_domain(49);
  start(launch_file("graph.yaml", {{"source", kSource}, {"sink", kSink}}), other);
  const auto [code, output] = doctor(domain, {"--domains", std::to_string(other)});
  EXPECT_EQ(code, 1) << output;
  EXPECT_NE(output.find(fmt::format("problem: nothing runs on DDS domain {}", domain)),
            std::string::npos)
      << output;
  EXPECT_NE(output.find(fmt::format("participant(s) on DDS domain {}, not {}: launch, sink, source",
                                    other, domain)),
            std::string::npos)
      << output;
  EXPECT_NE(output.find(fmt::format("MOCAP_DOMAIN_ID={}", other)), std::string::npos) << output;
}

TEST_F(Doctor, NamesParticipantsThatUseDdsSecurity) {
  const int domain = test::test_domain(50);
  const auto credentials = dir_ / "credentials";
  auto [made, made_output] =
      test::run_command({"bash", (test::source_dir() / "scripts" / "make_security.sh").string(),
                         credentials.string(), "graph", "doctor"});
  ASSERT_EQ(made, 0) << made_output;
  const auto file = launch_file(
      "graph.yaml", {{"source", kSource}, {"sink", kSink}},
      fmt::format("{{security: {{directory: \"{}\", identity: graph}}}}", credentials.string()));
  start(file, domain).wait_for_output("received 20", std::chrono::seconds(30));
  const auto [code, output] = doctor(domain);
  EXPECT_EQ(code, 1) << output;
  // The launcher's own participant ("launch", which publishes its restarts) too.
  EXPECT_NE(output.find("use DDS Security: launch, sink, source; without credentials none of "
                        "their topics can be seen. Do: run the doctor with --security DIR "
                        "--identity"),
            std::string::npos)
      << output;
  // With credentials of the graph's authority, it sees through, given the time to authenticate
  // with each participant (seconds under AddressSanitizer beside other tests).
  const auto [seen_code, seen] = doctor(domain, {file.string(), "--security", credentials.string(),
                                                 "--identity", "doctor", "--seconds", "12"});
  EXPECT_EQ(seen_code, 0) << seen;
  EXPECT_NE(seen.find("all well"), std::string::npos) << seen;
}

TEST_F(Doctor, NamesAHostWhoseClockDisagrees) {
  const std::filesystem::path faketime = "/usr/lib/x86_64-linux-gnu/faketime/libfaketimeMT.so.1";
  ASSERT_TRUE(std::filesystem::exists(faketime))
      << faketime << " is missing: scripts/install_deps.sh test installs faketime";
  const int domain = test::test_domain(51);
  start(launch_file("sink.yaml", {{"sink", kSink}}), domain);
  start(launch_file("source.yaml", {{"source", kSource}}), domain, {},
        {{"LD_PRELOAD", faketime.string()},
         {"FAKETIME", "+0.005"},
         {"FAKETIME_DONT_FAKE_MONOTONIC", "1"}});
  const auto [code, output] = doctor(domain);
  EXPECT_EQ(code, 1) << output;
  std::smatch ahead;
  ASSERT_TRUE(std::regex_search(
      output, ahead,
      std::regex(R"(problem: the clock of source on \S+ is ([0-9.]+) ms ahead of this host's)")))
      << output;
  std::printf("source's clock measured %s ms ahead (set 5 ms ahead)\n", ahead[1].str().c_str());
  EXPECT_NEAR(std::stod(ahead[1]), 5.0, 0.1) << output;
  EXPECT_EQ(output.find("the clock of sink"), std::string::npos) << output;
}

TEST_F(Doctor, NamesAComponentWhoseCallbacksDoNotRun) {
  const int domain = test::test_domain(52);
  start(launch_file("graph.yaml", {{"device", R"(
      - plugin: stuck_callback
        name: reader
)"}}),
        domain);
  const auto [code, output] = doctor(domain);
  EXPECT_EQ(code, 1) << output;
  EXPECT_NE(output.find("problem: device/reader is STALE: no report for"), std::string::npos)
      << output;
  EXPECT_NE(output.find("its callbacks do not run"), std::string::npos) << output;
}

}  // namespace
}  // namespace mocap
