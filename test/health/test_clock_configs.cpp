// The chrony configurations the README gives for the hosts' clocks (config/clock/), read by
// chrony itself: `chronyd -p` parses a file and prints it, and fails on a directive it does not
// know or cannot read.
#include <gtest/gtest.h>

#include "test/test_support.hpp"

namespace mocap {
namespace {

constexpr const char* kChronyd = "/usr/sbin/chronyd";

std::pair<int, std::string> parse(const std::filesystem::path& file) {
  return test::run_command({kChronyd, "-p", "-f", file.string()}, {}, std::chrono::seconds(20));
}

TEST(ClockConfigs, ChronyReadsTheFusionAndCameraHostsConfigurations) {
  ASSERT_TRUE(std::filesystem::exists(kChronyd))
      << "chrony is missing: scripts/install_deps.sh test installs it";
  for (const char* name : {"chrony_fusion_host.conf", "chrony_camera_host.conf"}) {
    const auto [code, output] = parse(test::source_dir() / "config" / "clock" / name);
    EXPECT_EQ(code, 0) << name << ": " << output;
    EXPECT_NE(output.find("hwtimestamp *"), std::string::npos) << output;
  }
  const auto [code, output] =
      parse(test::source_dir() / "config" / "clock" / "chrony_camera_host.conf");
  EXPECT_NE(output.find("minpoll 0 maxpoll 4 xleave"), std::string::npos) << output;
  // A parse that can fail: a misspelled directive is refused with its line.
  test::TempDir dir;
  const auto broken = dir / "broken.conf";
  test::write_file(broken, "server 192.168.1.10 iburst\nmakestep 0.1 3 x\n");
  const auto [broken_code, broken_output] = parse(broken);
  EXPECT_NE(broken_code, 0) << broken_output;
  EXPECT_NE(broken_output.find("line 2"), std::string::npos) << broken_output;
}

}  // namespace
}  // namespace mocap
