// The multi-host deployment (launch_yaml/distributed/tracking.yaml): its launch file, the
// scenario's check (scripts/scenario.sh), the scenario on four network namespaces with a
// crashed host and a lost link (scripts/netns_scenario.sh), and the Docker files that run the
// same scenario in containers (docker/).
#include <gtest/gtest.h>

#include <signal.h>

#include <algorithm>
#include <chrono>
#include <filesystem>
#include <regex>
#include <set>
#include <sstream>

#include <fmt/format.h>

#include "test/test_support.hpp"

namespace mocap {
namespace {
namespace fs = std::filesystem;

constexpr const char* kRoles[] = {"sensor", "compute", "robot", "observer"};

fs::path repo(std::string_view relative) { return test::source_dir() / relative; }

std::string launch_file() { return repo("launch_yaml/distributed/tracking.yaml").string(); }

std::map<std::string, std::string> environment(int slot) {
  return {{"MOCAP_DOMAIN_ID", std::to_string(test::test_domain(slot))},
          {"MOCAP_BIN_DIR", test::bin_dir().string()}};
}

std::vector<std::string> lines_of(const std::string& text) {
  std::vector<std::string> lines;
  std::istringstream in(text);
  for (std::string line; std::getline(in, line);) lines.push_back(line);
  return lines;
}

// The first line that starts with `prefix`, or "".
std::string line_starting(const std::string& text, std::string_view prefix) {
  for (const std::string& line : lines_of(text)) {
    if (line.starts_with(prefix)) return line;
  }
  return "";
}

std::vector<std::string> words(std::string_view text) {
  std::vector<std::string> out;
  std::istringstream in{std::string(text)};
  for (std::string word; in >> word;) out.push_back(word);
  return out;
}

TEST(Distributed, LaunchFileHasAGroupPerHost) {
  for (const char* role : kRoles) {
    auto [code, output] = test::run_command(
        {(test::bin_dir() / "mocap_launch").string(), launch_file(), "--group", role, "--check"},
        environment(81));
    EXPECT_EQ(code, 0) << role << ": " << output;
    EXPECT_NE(output.find("valid (4 group(s)"), std::string::npos) << output;
  }
  // The hosts share no memory: every sample between groups travels over UDP.
  EXPECT_NE(test::read_file(launch_file()).find("shared_memory: false"), std::string::npos);
}

// Without a publisher the check gives up at its deadline with a FAIL verdict and status 1.
TEST(Distributed, CheckFailsAtItsDeadlineWithoutPoses) {
  auto start = std::chrono::steady_clock::now();
  auto [code, output] =
      test::run_command({repo("scripts/scenario.sh").string(), "check", "--timeout", "3"},
                        environment(82), std::chrono::seconds(60));
  double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(code, 1) << output;
  EXPECT_NE(line_starting(output, "check: FAIL no publisher of /mocap/poses found"), "") << output;
  EXPECT_LT(elapsed_s, 20) << output;
}

// The four groups as processes of this machine (no namespaces, no root): the check sees the
// poses the pipeline makes across them.
TEST(Distributed, CheckPassesWhenTheGroupsRunAsProcesses) {
  test::TempDir dir;
  std::string servos = (dir / "servos").string();
  test::ChildProcess launch(
      {(test::bin_dir() / "mocap_launch").string(), launch_file(), "--duration", "90", "--set",
       "servos.device_link=" + servos, "--set", "turret.port=" + servos},
      environment(83), dir / "launch.log");
  auto [code, output] =
      test::run_command({repo("scripts/scenario.sh").string(), "check", "--timeout", "45"},
                        environment(83), std::chrono::seconds(90));
  launch.signal(SIGTERM);
  EXPECT_EQ(code, 0) << output << launch.output();
  std::string verdict = line_starting(output, "check: PASS 30 of 30 pose arrays with poses");
  EXPECT_NE(verdict, "") << output;
  EXPECT_NE(verdict.find("board_a"), std::string::npos) << verdict;
  EXPECT_EQ(launch.wait(std::chrono::seconds(30)), 0) << launch.output();
}

// Four hosts in network namespaces on a bridge: poses reach the observer; after the compute
// host is killed and started again they do again, and after its link goes down and up (longer
// than the DDS lease) they do again, the other hosts untouched; while each fault lasts none
// arrive. The robot follows the board again after each. Then nothing is left behind.
TEST(Distributed, FourHostsRecoverFromACrashAndALostLink) {
  auto start = std::chrono::steady_clock::now();
  // Bounded: three checks of at most 20 s, two of 3 s, the link down 7 s, start and stop.
  auto [code, output] = test::run_command({repo("scripts/netns_scenario.sh").string(), "--faults",
                                           "--keep-going", "--check-timeout", "20"},
                                          environment(80), std::chrono::seconds(120));
  if (code == 77) GTEST_SKIP() << output;
  double elapsed_s =
      std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
  EXPECT_EQ(code, 0) << output;

  // Poses crossed the network: the observer host received them on its link.
  std::string first = line_starting(output, "phase start: ");
  EXPECT_TRUE(first.starts_with("phase start: PASS check: PASS 30 of 30")) << output;
  std::smatch received;
  ASSERT_TRUE(std::regex_search(first, received, std::regex(R"(observer link received (\d+) KiB)")))
      << first;
  EXPECT_GT(std::stoll(received[1]), 10) << first;

  std::string crash = line_starting(output, "phase kill_compute: ");
  EXPECT_TRUE(crash.starts_with("phase kill_compute: PASS")) << output;
  EXPECT_NE(crash.find("no poses meanwhile"), std::string::npos) << crash;
  EXPECT_NE(crash.find("check: PASS"), std::string::npos) << crash;

  std::string link = line_starting(output, "phase link_compute: ");
  EXPECT_TRUE(link.starts_with("phase link_compute: PASS")) << output;
  EXPECT_NE(link.find("no poses meanwhile"), std::string::npos) << link;
  EXPECT_NE(link.find("check: PASS"), std::string::npos) << link;

  // After each, the robot follows the board again and the observer's evaluator evaluates.
  for (const std::string& phase : {first, crash, link}) {
    EXPECT_NE(phase.find("robot following, observer evaluating"), std::string::npos) << phase;
  }
  EXPECT_NE(line_starting(output, "result: PASS 3 of 3 phases"), "") << output;
  EXPECT_LT(elapsed_s, 110) << output;

  // Cleaned up: no namespace of this run remains.
  std::smatch run;
  ASSERT_TRUE(std::regex_search(output, run, std::regex(R"(namespaces (mgtest_\d+)_)"))) << output;
  auto [list_code, namespaces] = test::run_command({"ip", "netns", "list"});
  EXPECT_EQ(list_code, 0) << namespaces;
  EXPECT_EQ(namespaces.find(run[1].str() + "_"), std::string::npos) << namespaces;
}

// docker/compose.yaml is a valid compose file with a service per host and the checker, each
// running its role through scripts/scenario.sh.
TEST(Distributed, ComposeFileHasAServicePerHostAndTheChecker) {
  std::string compose = repo("docker/compose.yaml").string();
  auto [version_code, version] = test::run_command({"docker-compose", "version"});
  ASSERT_EQ(version_code, 0) << "docker-compose is missing (scripts/install_deps.sh installs it): "
                             << version;
  auto [code, config] = test::run_command({"docker-compose", "-f", compose, "config"});
  ASSERT_EQ(code, 0) << config;
  auto [services_code, services] =
      test::run_command({"docker-compose", "-f", compose, "config", "--services"});
  ASSERT_EQ(services_code, 0) << services;
  std::vector<std::string> listed = words(services);
  std::sort(listed.begin(), listed.end());
  EXPECT_EQ(listed, (std::vector<std::string>{"checker", "compute", "observer", "robot", "sensor"}))
      << services;
  // Each host runs its own role; the checker the check, and never restarts.
  for (const char* role : kRoles) {
    EXPECT_NE(config.find(fmt::format("command:\n    - scenario.sh\n    - {}\n", role)),
              std::string::npos)
        << role << "\n"
        << config;
  }
  EXPECT_NE(config.find("command:\n    - scenario.sh\n    - check\n"), std::string::npos) << config;
  EXPECT_NE(config.find("restart: \"no\""), std::string::npos) << config;
}

// The Dockerfile's build stage installs what building and packaging need (groups of the one
// package list, scripts/install_deps.sh) and builds the Debian package, unless it is given one
// (MOCAP_DEB); the runtime stage installs that package (test/install/debian_package.sh proves
// it installs and runs in a clean Debian 12 root).
TEST(Distributed, DockerImageIsTheDebianPackage) {
  std::string dockerfile = test::read_file(repo("docker/Dockerfile"));
  ASSERT_FALSE(dockerfile.empty());
  const std::string install = "scripts/install_deps.sh build package";
  const std::string groups = test::read_file(repo("scripts/install_deps.sh"));
  EXPECT_NE(groups.find("\nbuild=("), std::string::npos) << groups;
  EXPECT_NE(groups.find("\npackage=("), std::string::npos) << groups;
  size_t build_stage = dockerfile.find("FROM debian:bookworm AS build");
  size_t runtime_stage = dockerfile.find("FROM debian:bookworm-slim");
  ASSERT_NE(build_stage, std::string::npos) << dockerfile;
  ASSERT_NE(runtime_stage, std::string::npos) << dockerfile;
  size_t install_at = dockerfile.find("\nRUN [ -n \"$MOCAP_DEB\" ] || " + install + "\n");
  size_t package_at = dockerfile.find("&& scripts/package.sh --runtime-only");
  EXPECT_NE(install_at, std::string::npos) << "RUN ... || " << install << "\n" << dockerfile;
  EXPECT_NE(dockerfile.find("cp \"$MOCAP_DEB\" build-package/"), std::string::npos) << dockerfile;
  EXPECT_TRUE(build_stage < install_at && install_at < package_at && package_at < runtime_stage)
      << dockerfile;
  size_t copy_at = dockerfile.find(
      "COPY --from=build /opt/mocap-graph/build-package/mocap-graph_*_amd64.deb", runtime_stage);
  size_t apt_at = dockerfile.find("apt-get install -y --no-install-recommends /tmp/mocap-graph_",
                                  runtime_stage);
  EXPECT_TRUE(copy_at != std::string::npos && apt_at != std::string::npos && copy_at < apt_at)
      << dockerfile;
  // The containers run the installed scenario script, as the namespaces run the tree's.
  EXPECT_NE(dockerfile.find("ENV PATH=/usr/share/mocap_graph/scripts:$PATH"), std::string::npos)
      << dockerfile;
  EXPECT_NE(test::read_file(repo("cmake/Install.cmake")).find("scripts/scenario.sh\n"),
            std::string::npos);
}

}  // namespace
}  // namespace mocap
